// src/models/fused_mlp_plan.h — the layout of a fused tanh MLP's jet
// (channels, the per-call plan of workspace offsets, the taped workspace) and
// the per-member GEMMs and workspace cache that fused_mlp.cpp and
// fused_mlp_gradient.cpp share. The layout itself is described at the top of
// fused_mlp.cpp. Private to src/models.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace phnn {
namespace internal {

// Channel bookkeeping of one jet.
struct Channels {
  int64_t d = 0, order = 0;
  std::vector<std::pair<int64_t, int64_t>> pairs;  // (i, j), i <= j

  Channels(int64_t directions, int64_t jet_order) : d(directions), order(jet_order) {
    if (order >= 2)
      for (int64_t i = 0; i < d; ++i)
        for (int64_t j = i; j < d; ++j) pairs.emplace_back(i, j);
  }
  int64_t count() const { return 1 + (order >= 1 ? d : 0) + static_cast<int64_t>(pairs.size()); }
  int64_t tangent(int64_t i) const { return 1 + i; }
  int64_t pair(std::size_t p) const { return 1 + d + static_cast<int64_t>(p); }
};

// Sizes of one call and where each saved buffer lives in the workspace.
struct Plan {
  Channels ch{0, 0};
  int64_t E = 0, B = 0;
  std::vector<int64_t> widths;  // n_0 .. n_L
  std::vector<int64_t> act, pre, tanh;  // offsets: A_l (l < L), Z_l and T_l (l < L - 1)
  int64_t out = 0, total = 0;           // Z_L, workspace size

  Plan(const Channels& channels, int64_t members, int64_t batch, std::vector<int64_t> sizes)
      : ch(channels), E(members), B(batch), widths(std::move(sizes)) {
    const int64_t C = ch.count();
    for (int64_t l = 0; l < layers(); ++l) {
      act.push_back(total);
      total += E * C * B * widths[l];
      if (l + 1 < layers()) {
        pre.push_back(total);
        total += E * C * B * widths[l + 1];
        tanh.push_back(total);
        total += E * B * widths[l + 1];
      }
    }
    out = total;
    total += E * C * B * widths.back();
  }
  int64_t layers() const { return static_cast<int64_t>(widths.size()) - 1; }
  int64_t rows() const { return ch.count() * B; }  // rows of a member's GEMM
  int64_t block(int64_t n) const { return rows() * n; }  // a member's [C, B, n]
};

/// The plan and workspace of a taped call (fused_mlp.h).
struct FusedMlpTape {
  Plan plan;
  torch::Tensor workspace;
};

/// Row-major per member: C[e] = A[e] B[e] with A [rows, k], B [k, cols]
/// (transpose_b: B[e] is stored as [cols, k]); member_gemm.h's kernel.
void gemm_nn(int64_t E, int rows, int k, int cols, const double* a, const double* b, double* c,
             bool transpose_b);

/// Per member: W~[e] (+)= A[e]^T Z~[e], A [rows, n_in], Z~ [rows, n_out].
void gemm_tn(int64_t E, int rows, int n_in, int n_out, const double* a, const double* z,
             double* w, bool accumulate);

/// A workspace buffer of `numel` doubles, reused across calls once nobody
/// else holds it (fused_mlp.cpp).
torch::Tensor reusable_buffer(int64_t numel);

}  // namespace internal
}  // namespace phnn
