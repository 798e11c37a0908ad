// src/training/regularizers.cpp — the Jacobian regularizers CN, SN, SR
// (phnn/training/regularizers.h, docs/METHOD.md §4).
#include "phnn/training/regularizers.h"

#include <cmath>
#include <limits>

#include "kernels/ordered_sum.h"
#include "training/jacobian_spectrum.h"

namespace phnn {
namespace {
constexpr double kFloor = 1e-300;  // safe_sqrt's float64 floor

// sqrt with a finite derivative at 0 (the clamped branch has zero slope).
// The floor is a positive normal number of the dtype: 1e-300 would round to 0
// in float32 (float32 training), where sqrt has an infinite slope.
torch::Tensor safe_sqrt(const torch::Tensor& s) {
  const double floor =
      s.scalar_type() == torch::kFloat32 ? std::numeric_limits<float>::min() : kFloor;
  return torch::sqrt(s.clamp_min(floor));
}
}  // namespace

JacobianStats jacobian_stats_general(const torch::Tensor& jacobian, double eps) {
  const int64_t n = jacobian.size(-1);
  const auto sigma = internal::singular_values(jacobian);  // descending
  JacobianStats out;
  out.sigma_max = sigma.select(-1, 0);
  out.sigma_min = sigma.select(-1, n - 1);
  out.kappa = out.sigma_max / (out.sigma_min + eps);
  const auto re = internal::eigenvalue_real_parts(jacobian).abs();
  out.rho = std::get<0>(re.max(-1)) / (std::get<0>(re.min(-1)) + eps);
  return out;
}

JacobianStats jacobian_stats(const torch::Tensor& jacobian, double eps) {
  if (jacobian.size(-1) != 2) return jacobian_stats_general(jacobian, eps);
  const auto a = jacobian.select(-2, 0).select(-1, 0);
  const auto b = jacobian.select(-2, 0).select(-1, 1);
  const auto c = jacobian.select(-2, 1).select(-1, 0);
  const auto d = jacobian.select(-2, 1).select(-1, 1);
  const auto s1 = safe_sqrt((a + d) * (a + d) + (c - b) * (c - b));
  const auto s2 = safe_sqrt((a - d) * (a - d) + (c + b) * (c + b));
  JacobianStats out;
  out.sigma_max = 0.5 * (s1 + s2);
  out.sigma_min = 0.5 * (s1 - s2).abs();
  out.kappa = out.sigma_max / (out.sigma_min + eps);
  const auto half_trace = 0.5 * (a + d);
  const auto disc = half_trace * half_trace - (a * d - b * c);
  const auto root = torch::where(disc > 0, safe_sqrt(disc), torch::zeros_like(disc));
  const auto re1 = (half_trace + root).abs(), re2 = (half_trace - root).abs();
  out.rho = torch::maximum(re1, re2) / (torch::minimum(re1, re2) + eps);
  return out;
}

torch::Tensor regularizer_penalty(Regularizer reg, const JacobianStats& stats,
                                  const TrainerOptions& options) {
  switch (reg) {
    case Regularizer::kCn: return options.lambda_cn * internal::ordered_mean(stats.kappa * stats.kappa, 1);
    case Regularizer::kSn: return options.lambda_sn * internal::ordered_mean(stats.sigma_max, 1);
    case Regularizer::kSr: {
      const auto r = stats.rho - 1.0;
      return options.lambda_sr * internal::ordered_mean(r * r, 1);
    }
    case Regularizer::kNone: break;
  }
  return torch::zeros({stats.kappa.size(0)}, stats.kappa.options());
}

namespace {

// ---- The n = 2 penalties with their adjoints, row by row (a row = one member
// and one batch element, J = [[a, b], [c, d]]): the operations of
// jacobian_stats and regularizer_penalty above and of their autograd
// backward, in the same order (an adjoint fed by several nodes is summed in
// the order autograd's engine runs them), so the same bits
// (tests/training/regularizers_test.cpp). Each returns the row's term of
// the mean and writes J~ for the term's adjoint g; autograd's J~ is a sum of
// four select adjoints over zeros, hence "+ 0.0" (-0 becomes +0).
// Backward rules: x*x -> g x + g x (exactly 2 g x), sqrt -> g / (2 sqrt),
// clamp_min -> g where x >= floor else 0, |x| -> g sgn(x), p / q ->
// (g / q, -g ((p / q) / q)), maximum/minimum -> g (g / 2 on ties) to the
// larger/smaller operand.
inline double clamp_floor(double q) { return q < kFloor ? kFloor : q; }
inline double sgn(double x) { return static_cast<double>((0.0 < x) - (x < 0.0)); }
inline void put(double* jb, double ab, double bb, double cb, double db) {
  jb[0] = ab + 0.0, jb[1] = bb + 0.0, jb[2] = cb + 0.0, jb[3] = db + 0.0;
}

// s1 = |(a + d, c - b)|, s2 = |(a - d, c + b)| (floored) and their backward
// from s1~, s2~ into J~.
struct SingularPair {
  double u1, u2, w1, w2, q1, q2, s1, s2;
  explicit SingularPair(const double* j)
      : u1(j[0] + j[3]), u2(j[2] - j[1]), w1(j[0] - j[3]), w2(j[2] + j[1]),
        q1(u1 * u1 + u2 * u2), q2(w1 * w1 + w2 * w2),
        s1(std::sqrt(clamp_floor(q1))), s2(std::sqrt(clamp_floor(q2))) {}
  // Each entry of J~ sums four adjoints (jacobian_stats writes each factor
  // of s1's and s2's squares as its own sum or difference), in the order
  // autograd runs their nodes: s2's (second factor first), then s1's.
  void backward(double s1b, double s2b, double* jb) const {
    const double q1b = q1 >= kFloor ? s1b / (2.0 * s1) : 0.0;
    const double q2b = q2 >= kFloor ? s2b / (2.0 * s2) : 0.0;
    const double u1b = q1b * u1, u2b = q1b * u2, w1b = q2b * w1, w2b = q2b * w2;
    put(jb, ((w1b + w1b) + u1b) + u1b, ((w2b + w2b) + -u2b) + -u2b, ((w2b + w2b) + u2b) + u2b,
        ((-w1b + -w1b) + u1b) + u1b);
  }
};

// CN: kappa^2, kappa = sigma_max / (sigma_min + eps).
double cn_row(const double* j, double g, double eps, double* jb) {
  const SingularPair s(j);
  const double sm = 0.5 * (s.s1 + s.s2), dd = s.s1 - s.s2, den = 0.5 * std::fabs(dd) + eps;
  const double kappa = sm / den;
  const double kb = g * kappa + g * kappa;
  const double smb = kb / den, denb = -kb * ((sm / den) / den);
  const double ddb = (denb * 0.5) * sgn(dd), sumb = smb * 0.5;
  s.backward(ddb + sumb, -ddb + sumb, jb);
  return kappa * kappa;
}

// SN: sigma_max.
double sn_row(const double* j, double g, double /*eps*/, double* jb) {
  const SingularPair s(j);
  s.backward(g * 0.5, g * 0.5, jb);
  return 0.5 * (s.s1 + s.s2);
}

// maximum/minimum's adjoint to operand x against y (is_max: maximum).
inline double extremum_adjoint(double g, double x, double y, bool is_max) {
  const double t = x == y ? g / 2.0 : g;
  return (is_max ? x < y : x > y) ? 0.0 : t;
}

// SR: (rho - 1)^2, rho = max|Re l| / (min|Re l| + eps), Re l = ht +- root.
double sr_row(const double* j, double g, double eps, double* jb) {
  const double a = j[0], b = j[1], c = j[2], d = j[3];
  const double ht = 0.5 * (a + d), ad = a * d, bc = b * c, disc = ht * ht - (ad - bc);
  const double s3 = std::sqrt(clamp_floor(disc)), root = disc > 0 ? s3 : 0.0;
  const double p1 = ht + root, m1 = ht - root, re1 = std::fabs(p1), re2 = std::fabs(m1);
  const bool nan = std::isnan(re1) || std::isnan(re2);  // maximum/minimum propagate NaN
  const double mx = nan ? re1 + re2 : re1 < re2 ? re2 : re1;
  const double mn = nan ? re1 + re2 : re1 > re2 ? re2 : re1;
  const double den = mn + eps, r = mx / den - 1.0;
  const double rb = g * r + g * r;
  const double mxb = rb / den, mnb = -rb * ((mx / den) / den);
  const double re1b =
      extremum_adjoint(mnb, re1, re2, false) + extremum_adjoint(mxb, re1, re2, true);
  const double re2b =
      extremum_adjoint(mnb, re2, re1, false) + extremum_adjoint(mxb, re2, re1, true);
  const double m1b = re2b * sgn(m1), p1b = re1b * sgn(p1);
  const double rootb = -m1b + p1b, s3b = disc > 0 ? rootb : 0.0;
  const double discb = disc >= kFloor ? s3b / (2.0 * s3) : 0.0;
  const double detb = -discb, bcb = -detb;
  // ht~: (ht - root)'s, (ht + root)'s, then ht * ht's two terms.
  const double htb = ((m1b + p1b) + discb * ht) + discb * ht, hsb = htb * 0.5;
  put(jb, detb * d + hsb, bcb * c, bcb * b, detb * a + hsb);
  return r * r;
}

// penalty_e = lambda (sum_b term_b) / B, term's adjoint lambda / B.
torch::Tensor penalty_2x2(Regularizer reg, double lambda, double eps, const torch::Tensor& dfdx,
                          torch::Tensor* dfdx_bar) {
  using Row = double (*)(const double*, double, double, double*);
  const Row row = reg == Regularizer::kCn ? cn_row : reg == Regularizer::kSn ? sn_row : sr_row;
  const torch::Tensor j = dfdx.contiguous();
  const int64_t E = j.size(0), B = j.size(1);
  torch::Tensor penalty = torch::empty({E}, j.options());
  *dfdx_bar = torch::empty_like(j);
  const double g = lambda / static_cast<double>(B);
  const double* pj = j.data_ptr<double>();
  double *pb = dfdx_bar->data_ptr<double>(), *pp = penalty.data_ptr<double>();
  for (int64_t e = 0; e < E; ++e) {
    double sum = 0.0;
    for (int64_t r = e * B; r < (e + 1) * B; ++r) sum += row(pj + 4 * r, g, eps, pb + 4 * r);
    pp[e] = lambda * (sum / static_cast<double>(B));
  }
  return penalty;
}

}  // namespace

JacobianPenalty jacobian_penalty_by_autograd(Regularizer reg, const TrainerOptions& options) {
  if (reg == Regularizer::kNone) return {};
  return [reg, options](const torch::Tensor& dfdx, torch::Tensor* dfdx_bar) {
    torch::AutoGradMode enable(true);
    const auto leaf = dfdx.detach().requires_grad_(true);
    const auto penalty =
        regularizer_penalty(reg, jacobian_stats(leaf, options.jacobian_eps), options);
    *dfdx_bar = torch::autograd::grad({penalty.sum()}, {leaf})[0];
    return penalty.detach();
  };
}

JacobianPenalty jacobian_penalty(Regularizer reg, const TrainerOptions& options) {
  if (reg == Regularizer::kNone) return {};
  const JacobianPenalty general = jacobian_penalty_by_autograd(reg, options);
  return [reg, options, general](const torch::Tensor& dfdx, torch::Tensor* dfdx_bar) {
    if (dfdx.size(-1) != 2 || dfdx.scalar_type() != torch::kFloat64) {
      return general(dfdx, dfdx_bar);
    }
    return penalty_2x2(reg, options.weight(reg), options.jacobian_eps, dfdx, dfdx_bar);
  };
}

}  // namespace phnn
