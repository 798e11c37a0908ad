// tests/models/phnn_s_jet_head_test.cpp — the PHNN-S field jet head
// (src/models/phnn_s_jet_head.cpp): it recognizes the structure of each of
// the paper's oscillators (else a regularized PHNN-S step would silently
// fall back to the slower op-by-op jet; the bits are pinned by
// ManualStepTest either way), and its field is the order-0 head's.
#include <array>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "models/fused_heads.h"
#include "phnn/systems/oscillators.h"

namespace phnn {
namespace internal {
namespace {

using Structure = std::array<std::array<double, 4>, 4>;

Structure structure_of(SystemKind kind) {
  const Oscillator oscillator(OscillatorOptions::defaults(kind));
  Structure S{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) S[r][c] = oscillator.S()(r, c);
  return S;
}

TEST(PhnnSJetHeadTest, RecognizesThePapersStructures) {
  EXPECT_EQ(phnn_s_jet_structure(structure_of(SystemKind::kHarmonic)),
            PhnnSJetStructure::kMechanical);
  EXPECT_EQ(phnn_s_jet_structure(structure_of(SystemKind::kDuffing)),
            PhnnSJetStructure::kMechanical);
  EXPECT_EQ(phnn_s_jet_structure(structure_of(SystemKind::kSelfSustained)),
            PhnnSJetStructure::kSelfSustained);
  Structure other = structure_of(SystemKind::kDuffing);
  other[1][3] = -2.0;  // another input gain
  EXPECT_EQ(phnn_s_jet_structure(other), PhnnSJetStructure::kOther);
}

// f of the jet head against phnn_s_field_forward (every coefficient of S
// times its column: the zero and unit products are exact, so the same bits
// for data without signed zeros), from the jet head's own w.
TEST(PhnnSJetHeadTest, FieldIsTheOrderZeroHeads) {
  torch::manual_seed(3);
  const int64_t E = 3, B = 17;
  const auto e = torch::randn({E, B, 2}, torch::kFloat64);
  const auto G = torch::randn({E, B, 2, 2}, torch::kFloat64);
  const auto u = torch::randn({E, B, 1}, torch::kFloat64);
  const auto l = torch::randn({E, B, 1}, torch::kFloat64);
  const auto l_g = torch::randn({E, B, 2, 1}, torch::kFloat64);
  for (const SystemKind kind : {SystemKind::kDuffing, SystemKind::kSelfSustained}) {
    const Structure S = structure_of(kind);
    const auto structure = phnn_s_jet_structure(S);
    const PhnnSWJet w = phnn_s_w_jet_forward(e, G, u, structure);
    EXPECT_TRUE(torch::equal(w.w, phnn_s_w_forward(e, u, {S[2][0], S[2][1], S[2][3]})));
    const JrFieldJet jet = phnn_s_field_jet_forward(e, G, u, l, l_g, w, structure);
    EXPECT_TRUE(torch::equal(jet.f, phnn_s_field_forward(e, u, l, w.w, S)))
        << to_string(kind);
    // The tangents: f_i = S_xx e_i + S_xw (2 l l_i w + l^2 w_i) (S_xu u has none); the
    // same bits, as doubling is exact and the zero and unit coefficients are too.
    for (int i = 0; i < 2; ++i) {
      const auto w_i = S[2][0] * G.select(2, i).narrow(-1, 0, 1) +
                       S[2][1] * G.select(2, i).narrow(-1, 1, 1);
      EXPECT_TRUE(torch::equal(w.w_g.select(2, i), w_i)) << to_string(kind);
      const auto z_i = 2.0 * l * l_g.select(2, i) * w.w + l * l * w.w_g.select(2, i);
      for (int c = 0; c < 2; ++c) {
        const auto expected = S[c][0] * G.select(2, i).narrow(-1, 0, 1) +
                              S[c][1] * G.select(2, i).narrow(-1, 1, 1) + S[c][2] * z_i;
        EXPECT_TRUE(torch::equal(jet.g.select(2, i).narrow(-1, c, 1), expected))
            << to_string(kind) << " direction " << i << " component " << c;
      }
    }
  }
}

}  // namespace
}  // namespace internal
}  // namespace phnn
