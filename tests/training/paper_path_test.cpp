// tests/training/paper_path_test.cpp — the paper path does not move: five
// paper cells (one per model-integrator, 200 Adam steps, seeds 0-1) give
// bitwise the inference MSE that the binary before the n-dimensional code
// (commit a6efecf) gave, `phnn train ... --seeds 0-1 --steps 200 --out`.
// Bits depend on OpenBLAS's run-time kernel (docs/BENCHMARKS.md): the values
// were recorded with the Haswell kernels; on another kernel set the test is
// skipped and says so.
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "phnn/training/trainer.h"

extern "C" char* openblas_get_corename() __attribute__((weak));

namespace phnn {
namespace {

struct GoldenCell {
  SystemKind system;
  ModelKind model;
  IntegratorKind integrator;
  int n_train;
  Regularizer regularizer;
  double mse[2];  // seeds 0 and 1
};

const GoldenCell kCells[] = {
    {SystemKind::kHarmonic, ModelKind::kNode, IntegratorKind::kRk2, 25, Regularizer::kNone, {3.7962419920977082, 1.2632659911840336}},
    {SystemKind::kDuffing, ModelKind::kPhnnJr, IntegratorKind::kRk2, 25, Regularizer::kCn, {8.0977154572573546, 76.306887880638357}},
    {SystemKind::kSelfSustained, ModelKind::kPhnnJr, IntegratorKind::kDg, 25, Regularizer::kNone,
     {0.026271335377200118, 0.025495383206884784}},
    {SystemKind::kDuffing, ModelKind::kPhnnS, IntegratorKind::kDg, 25, Regularizer::kSr, {8889.1077886803014, 640.63188267569296}},
    {SystemKind::kHarmonic, ModelKind::kPhnnS, IntegratorKind::kRk2, 100, Regularizer::kSn, {19.64864957278904, 32.76998698776147}},
};

TEST(PaperPathTest, FivePaperCellsGiveTheStoredMseBitwise) {
  const std::string core = openblas_get_corename != nullptr ? openblas_get_corename() : "";
  if (core != "Haswell") {
    GTEST_SKIP() << "stored values are for OpenBLAS's Haswell kernels; this machine uses \"" << core
                 << "\"";
  }
  for (const GoldenCell& g : kCells) {
    CellSpec cell;
    cell.model = g.model;
    cell.integrator = g.integrator;
    cell.n_train = g.n_train;
    cell.regularizer = g.regularizer;
    cell.seeds = {0, 1};
    cell.training.steps = 200;
    const SystemData data =
        make_system_data(OscillatorOptions::defaults(g.system), DatasetOptions{}, g.n_train);
    const auto results = train_cell(cell, data);
    for (int e = 0; e < 2; ++e) {
      EXPECT_EQ(results[static_cast<std::size_t>(e)].mse, g.mse[e])
          << to_string(g.system) << " " << model_label(g.model, g.integrator) << " seed " << e;
    }
  }
}

}  // namespace
}  // namespace phnn
