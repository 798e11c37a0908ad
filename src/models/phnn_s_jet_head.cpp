// src/models/phnn_s_jet_head.cpp — PHNN-S's field and its x-derivatives
// (first-order jet) around the L_z network, row by row, for the hand-written
// regularized steps (manual_step.cpp). The autograd path builds this jet op
// by op (PhnnS::field_from_effort at order 1: Jet lincombs of the structure
// rows, jet_mul twice, Jet::cat); these functions repeat its operations in
// its order, forward and backward, for the two structures of the paper's
// oscillators (docs/METHOD.md §1), so the results are autograd's bits
// (tests/models/manual_step_test.cpp). Per row, directions i = 0, 1:
//   w = S_w (e, u),  l = L_z(w),  ll = l l,  z = ll w,
//   (ll)_i = l_i l + l_i l,  z_i = (ll)_i w + w_i ll,
//   harmonic, Duffing:  w = e_1,  f = (e_1, -e_0 - z - u);
//   self-sustained:     w = -e_0 - u,  f = (-e_1 + z, e_0).
// A coefficient -1 is a product with -1 and u's tangent a zero times -1
// (-0), as in jet_scale; a zero coefficient leaves its term out (lincomb).
// The backward sums each adjoint in the order autograd's engine does (of the
// nodes ready at once, the one created last runs first), with narrow's zero
// padding (+0.0 added: -0 becomes +0 where two slices meet) and
// ordered_broadcast_mul's direction sums (0 + p_0) + p_1.
#include "models/fused_heads.h"
#include "models/fused_heads_common.h"

namespace phnn {
namespace internal {
namespace {

using namespace heads;

bool rows_equal(const std::array<std::array<double, 4>, 4>& S,
                const std::array<std::array<double, 4>, 3>& rows) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      if (S[r][c] != rows[r][c]) return false;
  return true;
}

}  // namespace

PhnnSJetStructure phnn_s_jet_structure(const std::array<std::array<double, 4>, 4>& S) {
  // Rows x_q, x_p, w of S (columns gradH_q, gradH_p, z, u); row y is not used.
  if (rows_equal(S, {{{0, 1, 0, 0}, {-1, 0, -1, -1}, {0, 1, 0, 0}}}))
    return PhnnSJetStructure::kMechanical;
  if (rows_equal(S, {{{0, -1, 1, 0}, {1, 0, 0, 0}, {-1, 0, 0, -1}}}))
    return PhnnSJetStructure::kSelfSustained;
  return PhnnSJetStructure::kOther;
}

PhnnSWJet phnn_s_w_jet_forward(const Tensor& e_in, const Tensor& g_in, const Tensor& u_in,
                               PhnnSJetStructure structure) {
  TORCH_CHECK(structure != PhnnSJetStructure::kOther,
              "phnn_s_w_jet_forward: not a structure of the paper's oscillators");
  const Tensor e = dense(e_in), G = dense(g_in), u = dense(u_in);
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  PhnnSWJet out{torch::empty({E, B, 1}, e.options()), torch::empty({E, B, 2, 1}, e.options())};
  const double *pe = e.data_ptr<double>(), *pg = G.data_ptr<double>(), *pu = u.data_ptr<double>();
  double *pw = out.w.data_ptr<double>(), *pwg = out.w_g.data_ptr<double>();
  const bool mechanical = structure == PhnnSJetStructure::kMechanical;
  for (int64_t r = 0; r < rows; ++r) {
    pw[r] = mechanical ? pe[2 * r + 1] : pe[2 * r] * -1.0 + pu[r] * -1.0;
    for (int i = 0; i < 2; ++i) {
      const double* gi = pg + 4 * r + 2 * i;
      pwg[2 * r + i] = mechanical ? gi[1] : gi[0] * -1.0 + 0.0 * -1.0;
    }
  }
  return out;
}

JrFieldJet phnn_s_field_jet_forward(const Tensor& e_in, const Tensor& g_in, const Tensor& u_in,
                                    const Tensor& l_in, const Tensor& lg_in, const PhnnSWJet& w_in,
                                    PhnnSJetStructure structure) {
  TORCH_CHECK(structure != PhnnSJetStructure::kOther,
              "phnn_s_field_jet_forward: not a structure of the paper's oscillators");
  const Tensor e = dense(e_in), G = dense(g_in), u = dense(u_in), l = dense(l_in),
               lg = dense(lg_in), w = dense(w_in.w), wg = dense(w_in.w_g);
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  JrFieldJet out{torch::empty({E, B, 2}, e.options()), torch::empty({E, B, 2, 2}, e.options())};
  const double *pe = e.data_ptr<double>(), *pg = G.data_ptr<double>(), *pu = u.data_ptr<double>();
  const double *pl = l.data_ptr<double>(), *plg = lg.data_ptr<double>();
  const double *pw = w.data_ptr<double>(), *pwg = wg.data_ptr<double>();
  double *pf = out.f.data_ptr<double>(), *pfg = out.g.data_ptr<double>();
  const bool mechanical = structure == PhnnSJetStructure::kMechanical;
  for (int64_t r = 0; r < rows; ++r) {
    const double lv = pl[r], wv = pw[r], llv = lv * lv, zv = llv * wv;
    const double e0 = pe[2 * r], e1 = pe[2 * r + 1];
    pf[2 * r] = mechanical ? e1 : e1 * -1.0 + zv;
    pf[2 * r + 1] = mechanical ? (e0 * -1.0 + zv * -1.0) + pu[r] * -1.0 : e0;
    for (int i = 0; i < 2; ++i) {
      const double lgi = plg[2 * r + i], llg = lgi * lv + lgi * lv;
      const double zg = llg * wv + pwg[2 * r + i] * llv;
      const double* gi = pg + 4 * r + 2 * i;
      double* fgi = pfg + 4 * r + 2 * i;
      fgi[0] = mechanical ? gi[1] : gi[1] * -1.0 + zg;
      fgi[1] = mechanical ? (gi[0] * -1.0 + zg * -1.0) + 0.0 * -1.0 : gi[0];
    }
  }
  return out;
}

// Backward, first half: from (f~, g~) to L_z's output adjoints, and the part
// of w's adjoint (harmonic, Duffing: e_1's) that arrives before L_z's.
PhnnSJetNetAdjoints phnn_s_field_jet_backward_net(const Tensor& f_bar, const Tensor& g_bar,
                                                  const Tensor& l_in, const Tensor& lg_in,
                                                  const PhnnSWJet& w_in,
                                                  PhnnSJetStructure structure) {
  const Tensor l = dense(l_in), lg = dense(lg_in), w = dense(w_in.w), wg = dense(w_in.w_g);
  const Tensor gb = dense(g_bar), fb = f_bar.defined() ? dense(f_bar) : Tensor();
  PhnnSJetNetAdjoints out{torch::empty_like(l), torch::empty_like(lg), torch::empty_like(w),
                          torch::empty_like(wg)};
  const double *pl = l.data_ptr<double>(), *plg = lg.data_ptr<double>();
  const double *pw = w.data_ptr<double>(), *pwg = wg.data_ptr<double>();
  const double *pgb = gb.data_ptr<double>(), *pfb = fb.defined() ? fb.data_ptr<double>() : nullptr;
  double *plb = out.l.data_ptr<double>(), *plgb = out.l_g.data_ptr<double>();
  double *pvb = out.w.data_ptr<double>(), *pwgb = out.w_g.data_ptr<double>();
  const bool mechanical = structure == PhnnSJetStructure::kMechanical;
  for (int64_t r = 0; r < l.numel(); ++r) {
    const double lv = pl[r], wv = pw[r], llv = lv * lv;
    double zgb[2], llg[2], llgb[2];
    for (int i = 0; i < 2; ++i) {
      const double* gbi = pgb + 4 * r + 2 * i;
      zgb[i] = mechanical ? gbi[1] * -1.0 : gbi[0];
      llg[i] = plg[2 * r + i] * lv + plg[2 * r + i] * lv;
      llgb[i] = zgb[i] * wv;
    }
    const double u3 = (0.0 + zgb[0] * llg[0]) + zgb[1] * llg[1];
    const double u4 = (0.0 + zgb[0] * pwg[2 * r]) + zgb[1] * pwg[2 * r + 1];
    double llvb = u4, wvb = u3;
    if (pfb) {
      const double zvb = mechanical ? pfb[2 * r + 1] * -1.0 : pfb[2 * r];
      llvb = u4 + zvb * wv;
      wvb = mechanical ? (pfb[2 * r] + u3) + zvb * llv : u3 + zvb * llv;
    }
    const double s = (0.0 + llgb[0] * plg[2 * r]) + llgb[1] * plg[2 * r + 1], m = llvb * lv;
    plb[r] = ((s + s) + m) + m;
    pvb[r] = wvb;
    for (int i = 0; i < 2; ++i) {
      plgb[2 * r + i] = llgb[i] * lv + llgb[i] * lv;
      const double m6 = zgb[i] * llv;
      pwgb[2 * r + i] = mechanical ? pgb[4 * r + 2 * i] + m6 : m6;
    }
  }
  return out;
}

// Backward, second half: with L_z's input adjoints (x~, x_g~) added to the
// first half's, the effort jet's adjoints (e~, G~).
PhnnSJetEffortAdjoints phnn_s_field_jet_backward_effort(const Tensor& f_bar, const Tensor& g_bar,
                                                        const PhnnSJetNetAdjoints& first,
                                                        const Tensor& x_bar,
                                                        const Tensor& xg_bar,
                                                        PhnnSJetStructure structure) {
  const Tensor gb = dense(g_bar), fb = f_bar.defined() ? dense(f_bar) : Tensor();
  const Tensor xb = dense(x_bar), xgb = dense(xg_bar);
  const int64_t E = gb.size(0), B = gb.size(1), rows = E * B;
  PhnnSJetEffortAdjoints out{torch::empty({E, B, 2}, gb.options()),
                             torch::empty({E, B, 2, 2}, gb.options())};
  const double *pgb = gb.data_ptr<double>(), *pfb = fb.defined() ? fb.data_ptr<double>() : nullptr;
  const double *pv = first.w.data_ptr<double>(), *pvg = first.w_g.data_ptr<double>();
  const double *pxb = xb.data_ptr<double>(), *pxgb = xgb.data_ptr<double>();
  double *peb = out.effort.data_ptr<double>(), *pGb = out.effort_g.data_ptr<double>();
  const bool mechanical = structure == PhnnSJetStructure::kMechanical;
  for (int64_t r = 0; r < rows; ++r) {
    const double wvb = pv[r] + pxb[r];  // harmonic, Duffing: e_1's adjoint
    if (mechanical) {
      peb[2 * r] = pfb ? 0.0 + pfb[2 * r + 1] * -1.0 : 0.0;
      peb[2 * r + 1] = pfb ? wvb + 0.0 : wvb;
    } else {
      const double eqb = pfb ? pfb[2 * r + 1] + wvb * -1.0 : wvb * -1.0;
      peb[2 * r] = pfb ? 0.0 + eqb : eqb;
      peb[2 * r + 1] = pfb ? pfb[2 * r] * -1.0 + 0.0 : 0.0;
    }
    for (int i = 0; i < 2; ++i) {
      const double* gbi = pgb + 4 * r + 2 * i;
      const double wgb = pvg[2 * r + i] + pxgb[2 * r + i];
      const double eqgb = mechanical ? gbi[1] * -1.0 : gbi[1] + wgb * -1.0;
      const double epgb = mechanical ? wgb : gbi[0] * -1.0;
      pGb[4 * r + 2 * i] = 0.0 + eqgb;
      pGb[4 * r + 2 * i + 1] = epgb + 0.0;
    }
  }
  return out;
}

}  // namespace internal
}  // namespace phnn
