// src/training/jacobian_spectrum.cpp — singular values and real parts of
// the eigenvalues by Eigen, with their first-order backward
// (src/training/jacobian_spectrum.h).
#include "training/jacobian_spectrum.h"

#include <complex>
#include <cstdint>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>

namespace phnn {
namespace internal {
namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;
using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// J as contiguous float64 matrices [R, n, n], no gradient.
torch::Tensor matrices_of(const torch::Tensor& jacobian) {
  const int64_t n = jacobian.size(-1);
  return jacobian.detach().to(torch::kFloat64).contiguous().reshape({-1, n, n});
}

// The forward's result: `values` [R, n] in J's batch shape [.., n] and
// dtype; J's shape is kept for the backward.
torch::Tensor values_like(AutogradContext* ctx, const torch::Tensor& jacobian,
                          const torch::Tensor& values) {
  ctx->saved_data["shape"] = jacobian.sizes().vec();
  std::vector<int64_t> shape = jacobian.sizes().vec();
  shape.pop_back();
  return values.reshape(shape).to(jacobian.scalar_type());
}

// The backward's result: `grad` [R, n, n] in J's shape and the gradient's dtype.
variable_list gradient_like(AutogradContext* ctx, const torch::Tensor& grad,
                            const torch::Tensor& upstream) {
  return {grad.reshape(ctx->saved_data["shape"].toIntVector()).to(upstream.scalar_type())};
}

// grad_J(a, b) = sum_k g_k (L(a, k) R(b, k) - L2(a, k) R2(b, k)) per matrix,
// k ascending (L2, R2 may be undefined: the real case).
torch::Tensor outer_sum(const torch::Tensor& g, const torch::Tensor& l, const torch::Tensor& r,
                        const torch::Tensor& l2, const torch::Tensor& r2) {
  const int64_t rows = l.size(0), n = l.size(1);
  const torch::Tensor gd = g.to(torch::kFloat64).contiguous().reshape({rows, n});
  torch::Tensor grad = torch::empty({rows, n, n}, l.options());
  const double *pg = gd.data_ptr<double>(), *pl = l.data_ptr<double>(), *pr = r.data_ptr<double>();
  const double* pl2 = l2.defined() ? l2.data_ptr<double>() : nullptr;
  const double* pr2 = r2.defined() ? r2.data_ptr<double>() : nullptr;
  double* out = grad.data_ptr<double>();
  for (int64_t m = 0; m < rows; ++m) {
    const int64_t base = m * n * n;
    for (int64_t a = 0; a < n; ++a) {
      for (int64_t b = 0; b < n; ++b) {
        double sum = 0.0;
        for (int64_t k = 0; k < n; ++k) {
          double term = pl[base + a * n + k] * pr[base + b * n + k];
          if (pl2) term -= pl2[base + a * n + k] * pr2[base + b * n + k];
          sum += pg[m * n + k] * term;
        }
        out[base + a * n + b] = sum;
      }
    }
  }
  return grad;
}

// sigma (descending) = Eigen's two-sided Jacobi SVD; d sigma_k / dJ = u_k v_k^T.
struct SingularValues : public torch::autograd::Function<SingularValues> {
  static torch::Tensor forward(AutogradContext* ctx, const torch::Tensor& jacobian) {
    const torch::Tensor in = matrices_of(jacobian);
    const int64_t rows = in.size(0), n = in.size(1);
    torch::Tensor sigma = torch::empty({rows, n}, in.options());
    torch::Tensor u = torch::empty({rows, n, n}, in.options()), v = torch::empty_like(u);
    const double* pin = in.data_ptr<double>();
    double *ps = sigma.data_ptr<double>(), *pu = u.data_ptr<double>(), *pv = v.data_ptr<double>();
    for (int64_t m = 0; m < rows; ++m) {
      const Eigen::Map<const RowMat> a(pin + m * n * n, n, n);
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
      for (int64_t k = 0; k < n; ++k) ps[m * n + k] = svd.singularValues()(k);
      Eigen::Map<RowMat>(pu + m * n * n, n, n) = svd.matrixU();
      Eigen::Map<RowMat>(pv + m * n * n, n, n) = svd.matrixV();
    }
    ctx->save_for_backward({u, v});
    return values_like(ctx, jacobian, sigma);
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list s = ctx->get_saved_variables();
    return gradient_like(ctx, outer_sum(grads[0], s[0], s[1], {}, {}), grads[0]);
  }
};

// lambda = Eigen's real Schur form (EigenSolver), J = V diag(lambda) V^-1;
// d Re(lambda_k) / dJ(a, b) = Re((V^-1)(k, a) V(b, k)).
struct EigenvalueRealParts : public torch::autograd::Function<EigenvalueRealParts> {
  static torch::Tensor forward(AutogradContext* ctx, const torch::Tensor& jacobian) {
    const torch::Tensor in = matrices_of(jacobian);
    const int64_t rows = in.size(0), n = in.size(1);
    torch::Tensor re = torch::empty({rows, n}, in.options());
    // left(a, k) = (V^-1)(k, a), right(b, k) = V(b, k): real and imaginary parts.
    torch::Tensor lr = torch::empty({rows, n, n}, in.options()), li = torch::empty_like(lr);
    torch::Tensor rr = torch::empty_like(lr), ri = torch::empty_like(lr);
    const double* pin = in.data_ptr<double>();
    double *pre = re.data_ptr<double>(), *plr = lr.data_ptr<double>(), *pli = li.data_ptr<double>();
    double *prr = rr.data_ptr<double>(), *pri = ri.data_ptr<double>();
    for (int64_t m = 0; m < rows; ++m) {
      const Eigen::Map<const RowMat> a(pin + m * n * n, n, n);
      const Eigen::EigenSolver<Eigen::MatrixXd> solver(a, true);
      const Eigen::MatrixXcd vec = solver.eigenvectors();
      const Eigen::MatrixXcd inv = vec.partialPivLu().inverse();
      const int64_t base = m * n * n;
      for (int64_t k = 0; k < n; ++k) {
        pre[m * n + k] = solver.eigenvalues()(k).real();
        for (int64_t i = 0; i < n; ++i) {
          plr[base + i * n + k] = inv(k, i).real();
          pli[base + i * n + k] = inv(k, i).imag();
          prr[base + i * n + k] = vec(i, k).real();
          pri[base + i * n + k] = vec(i, k).imag();
        }
      }
    }
    ctx->save_for_backward({lr, rr, li, ri});
    return values_like(ctx, jacobian, re);
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list s = ctx->get_saved_variables();
    return gradient_like(ctx, outer_sum(grads[0], s[0], s[1], s[2], s[3]), grads[0]);
  }
};

}  // namespace

torch::Tensor singular_values(const torch::Tensor& jacobian) {
  return SingularValues::apply(jacobian);
}

torch::Tensor eigenvalue_real_parts(const torch::Tensor& jacobian) {
  return EigenvalueRealParts::apply(jacobian);
}

}  // namespace internal
}  // namespace phnn
