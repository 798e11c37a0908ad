// bench/bench_training.cpp — training cost per member-step (not a test).
// Size: one benchmark binary, one mode per table of docs/BENCHMARKS.md.
//
//   bench_training stacked [repeats]   µs per member-step, every model x
//                                      integrator, +-CN, E = 1 and E = 10
//   bench_training baseline [repeats]  one small PHNN-JR-RK2 per step, plain
//                                      torch::nn + autograd create_graph for gradH
//   bench_training compare [repeats] [size]  fused vs reference networks,
//                                      interleaved, E = 10
//   bench_training precision [repeats] float32 training (reference networks)
//                                      vs float64 fused and reference, the
//                                      four PHNNs of the ablation, E = 10
//   bench_training run MODEL INTEGRATOR REG STEPS [SIZE] [N_TRAIN]   one cell, E = 10
//                                      (for perf; PHNN_REFERENCE_NETWORKS=1
//                                      selects the reference networks)
//   bench_training general [repeats]   n-dimensional models on mass chains of
//                                      n_x = 2, 4, 6, 8 states (system files
//                                      made in memory), E = 10, µs per
//                                      member-step; at n_x = 2 the built-in
//                                      harmonic oscillator's fused path beside
//                                      the general path on the same system
//   bench_training general-run K MODEL INTEGRATOR REG STEPS   one cell of the
//                                      n-dimensional models on a chain of K
//                                      masses, E = 10 (for perf)
//   bench_training cell                one full cell: small PHNN-JR-RK2,
//                                      E = 10, 50 000 steps (+ inference)
//
// Cost per member-step of the stacked trainer is measured as
//   (T(steps = 1200) - T(steps = 200)) / (1000 E)
// with train_cell itself, so evaluation and inference cancel out and what
// remains is the minibatch step (forward, regularizer, backward, Adam).
// bench/run_benchmarks.sh runs it under OpenBLAS + jemalloc and under
// Debian's defaults (reference BLAS, glibc malloc), side by side.
#include <algorithm>
#include <chrono>
#include <numeric>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <torch/torch.h>

#include "kernels/member_gemm.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/systems/system_file.h"
#include "phnn/training/trainer.h"

namespace {

using Clock = std::chrono::steady_clock;
using phnn::CellSpec;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A built-in system's data set with its system (the shipped file).
struct BuiltinData {
  std::shared_ptr<const phnn::PhSystem> system;
  phnn::PhSystemData data;
};
BuiltinData builtin_data(phnn::SystemKind kind, const phnn::DatasetOptions& options, int n_train) {
  BuiltinData d;
  d.system = phnn::builtin_system(phnn::OscillatorOptions::defaults(kind), options);
  d.data = phnn::make_ph_system_data(*d.system, options, n_train);
  return d;
}
std::vector<phnn::RunResult> train_cell(const CellSpec& cell, const BuiltinData& d) {
  return phnn::train_cell(cell, d.data, *d.system);
}

const BuiltinData& bench_data() {
  static const BuiltinData data = [] {
    phnn::DatasetOptions options;
    options.num_validation = 64;
    options.num_inference = 1;
    return builtin_data(phnn::SystemKind::kDuffing, options, 100);
  }();
  return data;
}

double time_cell(CellSpec cell, int steps) {
  cell.training.steps = steps;
  cell.training.eval_every = 1000000;
  const auto t0 = Clock::now();
  train_cell(cell, bench_data());
  return seconds_since(t0);
}

// Every model x integrator of the paper.
const std::pair<phnn::ModelKind, phnn::IntegratorKind> kModels[] = {
    {phnn::ModelKind::kNode, phnn::IntegratorKind::kRk2},
    {phnn::ModelKind::kPhnnJr, phnn::IntegratorKind::kRk2},
    {phnn::ModelKind::kPhnnJr, phnn::IntegratorKind::kDg},
    {phnn::ModelKind::kPhnnS, phnn::IntegratorKind::kRk2},
    {phnn::ModelKind::kPhnnS, phnn::IntegratorKind::kDg}};

// Fused networks against the op-by-op reference path, interleaved run by
// run in one process (E = 10, batch 64): the before/after of the fused node.
int compare(int repeats, phnn::ModelSize size) {
  std::printf("size %s, E = 10, µs per member-step, median of %d interleaved runs\n",
              phnn::to_string(size).c_str(), repeats);
  std::printf("| model | regularizer | reference | fused | speed-up |\n|---|---|---|---|---|\n");
  for (const auto& [model, integrator] : kModels) {
    for (phnn::Regularizer reg : {phnn::Regularizer::kNone, phnn::Regularizer::kCn}) {
      CellSpec cell;
      cell.model = model;
      cell.integrator = integrator;
      cell.size = size;
      cell.n_train = 64;
      cell.regularizer = reg;
      cell.seeds = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
      const int short_steps = size == phnn::ModelSize::kSmall ? 200 : 50;
      const int long_steps = size == phnn::ModelSize::kSmall ? 1200 : 300;
      std::vector<double> samples[2];
      for (int r = 0; r < repeats; ++r) {
        for (int fused : {0, 1}) {
          cell.fused_networks = fused;
          const double t_short = time_cell(cell, short_steps), t_long = time_cell(cell, long_steps);
          samples[fused].push_back((t_long - t_short) / ((long_steps - short_steps) * 10.0) * 1e6);
        }
      }
      const double ref = median(samples[0]), fused = median(samples[1]);
      std::printf("| %s | %s | %.0f | %.0f | %.2fx |\n",
                  phnn::model_label(model, integrator).c_str(), phnn::to_string(reg).c_str(), ref,
                  fused, ref / fused);
      std::fflush(stdout);
    }
  }
  return 0;
}

// Float32 training (`[training] precision`, always on the reference
// networks) against float64 on the fused and on the reference networks,
// interleaved run by run (small, E = 10, batch 64, no regularizer): the
// cost of the precision ablation, and how much of it is the network path.
int precision(int repeats) {
  std::printf("small, E = 10, µs per member-step, median of %d interleaved runs\n", repeats);
  std::printf("| model | float64 fused | float64 reference | float32 | float32 / float64 fused |\n"
              "|---|---|---|---|---|\n");
  const std::pair<phnn::ModelKind, phnn::IntegratorKind> models[] = {
      {phnn::ModelKind::kPhnnJr, phnn::IntegratorKind::kRk2},
      {phnn::ModelKind::kPhnnJr, phnn::IntegratorKind::kDg},
      {phnn::ModelKind::kPhnnS, phnn::IntegratorKind::kRk2},
      {phnn::ModelKind::kPhnnS, phnn::IntegratorKind::kDg}};
  for (const auto& [model, integrator] : models) {
    CellSpec cell;
    cell.model = model;
    cell.integrator = integrator;
    cell.n_train = 64;
    cell.seeds = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    std::vector<double> samples[3];
    for (int r = 0; r < repeats; ++r) {
      for (int variant = 0; variant < 3; ++variant) {
        cell.fused_networks = variant == 0;
        cell.training.precision =
            variant == 2 ? phnn::Precision::kFloat32 : phnn::Precision::kFloat64;
        const double t_short = time_cell(cell, 200), t_long = time_cell(cell, 1200);
        samples[variant].push_back((t_long - t_short) / (1000.0 * 10.0) * 1e6);
      }
    }
    const double fused = median(samples[0]), reference = median(samples[1]),
                 f32 = median(samples[2]);
    std::printf("| %s | %.0f | %.0f | %.0f | %.2fx |\n",
                phnn::model_label(model, integrator).c_str(), fused, reference, f32, f32 / fused);
    std::fflush(stdout);
  }
  return 0;
}

int stacked(int repeats) {
  std::printf("| model | regularizer | E = 1 [µs/member-step] | E = 10 [µs/member-step] |\n");
  std::printf("|---|---|---|---|\n");
  for (const auto& [model, integrator] : kModels) {
    for (phnn::Regularizer reg : {phnn::Regularizer::kNone, phnn::Regularizer::kCn}) {
      double us[2];
      int k = 0;
      for (int members : {1, 10}) {
        CellSpec cell;
        cell.model = model;
        cell.integrator = integrator;
        cell.n_train = 64;  // batch 64
        cell.regularizer = reg;
        cell.seeds.clear();
        for (int s = 0; s < members; ++s) cell.seeds.push_back(s);
        std::vector<double> samples;
        for (int r = 0; r < repeats; ++r) {
          const double t_short = time_cell(cell, 200), t_long = time_cell(cell, 1200);
          samples.push_back((t_long - t_short) / (1000.0 * members) * 1e6);
        }
        us[k++] = median(samples);
      }
      std::printf("| %s | %s | %.0f | %.0f |\n", phnn::model_label(model, integrator).c_str(),
                  phnn::to_string(reg).c_str(), us[0], us[1]);
      std::fflush(stdout);
    }
  }
  return 0;
}

// ----------------------------------------------------------------- baseline
// One small PHNN-JR (L_H 2-16-16-3, L_R 3-16-16-6) as plain torch::nn
// modules, gradH by autograd with create_graph, RK2, L1 loss, Adam, batch 64.
struct Mlp : torch::nn::Module {
  Mlp(int in, int out) {
    l1 = register_module("l1", torch::nn::Linear(in, 16));
    l2 = register_module("l2", torch::nn::Linear(16, 16));
    l3 = register_module("l3", torch::nn::Linear(16, out));
  }
  torch::Tensor forward(const torch::Tensor& x) {
    return l3(torch::tanh(l2(torch::tanh(l1(x)))));
  }
  torch::nn::Linear l1{nullptr}, l2{nullptr}, l3{nullptr};
};

struct BaselinePhnnJr {
  std::shared_ptr<Mlp> lh = std::make_shared<Mlp>(2, 3), lr = std::make_shared<Mlp>(3, 6);
  torch::Tensor field(torch::Tensor x, const torch::Tensor& u) {
    if (!x.requires_grad()) x = x.detach().requires_grad_(true);
    const auto o = lh->forward(x);
    const auto q = x.select(-1, 0), p = x.select(-1, 1);
    const auto v0 = torch::softplus(o.select(-1, 0)) * q;
    const auto v1 = o.select(-1, 1) * q + torch::softplus(o.select(-1, 2)) * p;
    const auto H = 0.5 * (v0 * v0 + v1 * v1);
    const auto grad = torch::autograd::grad({H.sum()}, {x}, {}, true, true)[0];
    const auto l = lr->forward(torch::cat({x, u}, -1));
    auto L = torch::zeros({x.size(0), 3, 3}, x.options());
    L.select(1, 0).select(1, 0).copy_(l.select(-1, 0));
    L.select(1, 1).select(1, 0).copy_(l.select(-1, 1));
    L.select(1, 1).select(1, 1).copy_(l.select(-1, 2));
    L.select(1, 2).select(1, 0).copy_(l.select(-1, 3));
    L.select(1, 2).select(1, 1).copy_(l.select(-1, 4));
    L.select(1, 2).select(1, 2).copy_(l.select(-1, 5));
    const auto R = torch::matmul(L.transpose(1, 2), L);
    const auto e = torch::cat({grad, u}, -1).unsqueeze(-1);
    auto J = torch::tensor({0.0, 1.0, 0.0, -1.0, 0.0, -1.0, 0.0, 1.0, 0.0}, x.options()).reshape({3, 3});
    return torch::matmul(J - R, e).squeeze(-1).narrow(-1, 0, 2);
  }
};

int baseline(int repeats) {
  torch::manual_seed(0);
  const auto& data = bench_data().data;
  auto X = torch::empty({64, 2}, torch::kFloat64), Xn = torch::empty({64, 2}, torch::kFloat64),
       U = torch::empty({64, 1}, torch::kFloat64);
  for (int i = 0; i < 64; ++i) {
    X[i][0] = data.train.x[i](0); X[i][1] = data.train.x[i](1);
    Xn[i][0] = data.train.x_next[i](0); Xn[i][1] = data.train.x_next[i](1);
    U[i][0] = data.train.u[i](0);
  }
  std::vector<double> samples;
  for (int r = 0; r < repeats; ++r) {
    BaselinePhnnJr model;
    model.lh->to(torch::kFloat64);
    model.lr->to(torch::kFloat64);
    std::vector<torch::Tensor> params = model.lh->parameters();
    for (auto& p : model.lr->parameters()) params.push_back(p);
    torch::optim::Adam adam(params, torch::optim::AdamOptions(1e-3));
    const double h = 0.01;
    auto step = [&] {
      const auto k1 = model.field(X, U);
      const auto x_hat = X + h * model.field(X + 0.5 * h * k1, U);
      const auto loss = ((Xn - x_hat).abs() / h).mean();
      adam.zero_grad();
      loss.backward();
      adam.step();
    };
    for (int i = 0; i < 100; ++i) step();  // warm-up
    const auto t0 = Clock::now();
    for (int i = 0; i < 1000; ++i) step();
    samples.push_back(seconds_since(t0) / 1000 * 1e6);
  }
  std::printf("baseline one-model-per-step small PHNN-JR-RK2 (autograd create_graph): %.0f µs/step\n",
              median(samples));
  return 0;
}

int full_cell() {
  phnn::DatasetOptions options;
  const auto data = builtin_data(phnn::SystemKind::kDuffing, options, 25);
  CellSpec cell;
  cell.model = phnn::ModelKind::kPhnnJr;
  cell.integrator = phnn::IntegratorKind::kRk2;
  cell.n_train = 25;
  cell.training.steps = 50000;
  cell.seeds = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  const auto t0 = Clock::now();
  const auto results = train_cell(cell, data);
  std::printf("full cell (Duffing, small PHNN-JR-RK2, N_train 25, E = 10, 50 000 steps, "
              "101 validations, inference): %.1f s\n", seconds_since(t0));
  return 0;
}

}  // namespace

// A chain of k unit masses (k = 1: the harmonic oscillator of the paper's
// parameters), springs to a wall and between neighbours, a damper on each,
// a force on the first: n_x = 2k, n_w = k, n_u = 1.
std::string chain_text(int k) {
  std::string states, ports, z, h = "k*q1^2/2";
  for (int i = 1; i <= k; ++i) {
    const std::string s = std::to_string(i);
    states += std::string(i > 1 ? ", " : "") + "\"q" + s + "\", \"p" + s + "\"";
    ports += std::string(i > 1 ? ", " : "") + "\"w" + s + "\"";
    z += std::string(i > 1 ? ", " : "") + "\"c*w" + s + "\"";
    h += " + p" + s + "^2/(2*m)";
    if (i > 1) h += " + k*(q" + s + " - q" + std::to_string(i - 1) + ")^2/2";
  }
  const int n = 2 * k + k + 1;
  std::vector<std::vector<int>> S(n, std::vector<int>(n, 0));
  for (int i = 0; i < k; ++i) {
    S[2 * i][2 * i + 1] = 1;   // dq = dH/dp
    S[2 * i + 1][2 * i] = -1;  // dp = -dH/dq - z (- u)
    S[2 * i + 1][2 * k + i] = -1;
    S[2 * k + i][2 * i + 1] = 1;  // w = dH/dp
  }
  S[1][n - 1] = -1;
  S[n - 1][1] = 1;  // y = dH/dp1
  std::string rows;
  for (int r = 0; r < n; ++r) {
    rows += r ? ", [" : "[";
    for (int c = 0; c < n; ++c) rows += (c ? ", " : "") + std::to_string(S[r][c]);
    rows += "]";
  }
  return "name = \"chain-" + std::to_string(k) + "\"\nstates = [" + states + "]\ninputs = [\"u\"]\nports = [" +
         ports + "]\nH = \"" + h + "\"\nz = [" + z + "]\nS = [" + rows +
         "]\n[parameters]\nm = 0.16\nk = 6.25\nc = 0.1473654459516189\n[initial]\nmethod = "
         "\"energy\"\nenergy = [0.1, 1.0]\n[control]\ndesign = \"constant\"\nrange = [[-1, 1]]\n";
}

double time_general_cell(CellSpec cell, const phnn::PhSystemData& data, const phnn::PhSystem& system,
                         int steps) {
  cell.training.steps = steps;
  cell.training.eval_every = 1000000;
  const auto t0 = Clock::now();
  phnn::train_cell(cell, data, system);
  return seconds_since(t0);
}

// µs per member-step, (T(700) - T(100)) / (600 E), medians of `repeats`;
// at n_x = 2 the built-in fused path on the same harmonic system, interleaved.
// The FLOP bound: the member GEMMs' multiply-adds per member-step (counted,
// the same difference), 2 FLOPs each, at kGhz x 16 FLOP/cycle (2 FMA units
// x 4 doubles x 2).
constexpr double kGhz = 3.7;  // this machine's EPYC (bench/pytorch_step.py)
int general(int repeats) {
  std::printf("| model | n_x | general µs/member-step | fused 2-state µs/member-step | GEMM "
              "MFLOP/member-step | FLOP bound µs | general / bound |\n");
  for (int k = 1; k <= 4; ++k) {
    const auto system = phnn::compile_system(chain_text(k), "chain.toml");
    phnn::DatasetOptions options;
    options.num_validation = 64;
    options.num_inference = 1;
    options.beta = 0.4;  // 40-step rollouts: T(700) - T(100) is the training steps alone
    const phnn::PhSystemData data = phnn::make_ph_system_data(*system, options, 100);
    const BuiltinData builtin = builtin_data(phnn::SystemKind::kHarmonic, options, 100);
    for (const auto& [model, integrator] : kModels) {
      CellSpec cell;
      cell.model = model;
      cell.integrator = integrator;
      cell.n_train = 64;
      cell.seeds = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
      std::vector<double> general_us, fused_us;
      double mflop = 0.0;
      for (int r = 0; r < repeats; ++r) {
        const std::uint64_t m0 = phnn::internal::gemm_multiply_adds();
        const double a = time_general_cell(cell, data, *system, 100);
        const std::uint64_t m1 = phnn::internal::gemm_multiply_adds();
        const double b = time_general_cell(cell, data, *system, 700);
        const std::uint64_t m2 = phnn::internal::gemm_multiply_adds();
        mflop = 2.0 * (static_cast<double>(m2 - m1) - static_cast<double>(m1 - m0)) / 6000.0 / 1e6;
        general_us.push_back((b - a) / 6000.0 * 1e6);
        if (k == 1) {
          cell.training.eval_every = 1000000;
          cell.training.steps = 100;
          auto t0 = Clock::now();
          train_cell(cell, builtin);
          const double c = seconds_since(t0);
          cell.training.steps = 700;
          t0 = Clock::now();
          train_cell(cell, builtin);
          fused_us.push_back((seconds_since(t0) - c) / 6000.0 * 1e6);
        }
      }
      const double bound_us = mflop * 1e6 / (kGhz * 1e9 * 16.0) * 1e6;
      std::printf("| %s | %d | %.0f | %s | %.2f | %.1f | %.1f× |\n",
                  phnn::model_label(model, integrator).c_str(), 2 * k, median(general_us),
                  k == 1 ? std::to_string(static_cast<int>(median(fused_us) + 0.5)).c_str() : "",
                  mflop, bound_us, median(general_us) / bound_us);
      std::fflush(stdout);
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  torch::set_num_threads(1);
  const std::string mode = argc > 1 ? argv[1] : "stacked";
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  if (mode == "inference") {  // inference [MODEL] [INTEGRATOR]: a small cell's rollouts
    phnn::DatasetOptions options;  // 100 inference trajectories x 500 steps (+ 2 figure ones)
    const auto data = builtin_data(phnn::SystemKind::kDuffing, options, 25);
    CellSpec cell;
    cell.model = phnn::parse_model(argc > 2 ? argv[2] : "phnn-jr");
    cell.integrator = phnn::parse_integrator(argc > 3 ? argv[3] : "dg");
    cell.n_train = 25;
    cell.seeds = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    cell.training.steps = 1;  // two validations on 2 500 pairs, then inference
    cell.training.eval_every = 1000000;
    const auto t0 = Clock::now();
    train_cell(cell, data);
    std::printf("%.3f s\n", seconds_since(t0));
    return 0;
  }
  if (mode == "stacked") return stacked(repeats);
  if (mode == "general-run" && argc > 6) {  // for perf: general-run K MODEL INTEGRATOR REG STEPS
    const auto system = phnn::compile_system(chain_text(std::atoi(argv[2])), "chain.toml");
    phnn::DatasetOptions options;
    options.num_validation = 64;
    options.num_inference = 1;
    options.beta = 0.4;
    const phnn::PhSystemData data = phnn::make_ph_system_data(*system, options, 100);
    CellSpec cell;
    cell.model = phnn::parse_model(argv[3]);
    cell.integrator = phnn::parse_integrator(argv[4]);
    cell.regularizer = phnn::parse_regularizer(argv[5]);
    cell.n_train = 64;
    cell.seeds = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    std::printf("%.3f s\n", time_general_cell(cell, data, *system, std::atoi(argv[6])));
    return 0;
  }
  if (mode == "run" && argc > 5) {  // for perf: run MODEL INTEGRATOR REG STEPS [SIZE] [N_TRAIN] [E]
    CellSpec cell;
    cell.model = phnn::parse_model(argv[2]);
    cell.integrator = phnn::parse_integrator(argv[3]);
    cell.regularizer = phnn::parse_regularizer(argv[4]);
    cell.size = phnn::parse_size(argc > 6 ? argv[6] : "small");
    cell.n_train = argc > 7 ? std::atoi(argv[7]) : 64;  // batch = min(n_train, 64)
    cell.seeds.resize(argc > 8 ? static_cast<std::size_t>(std::atoi(argv[8])) : 10);
    std::iota(cell.seeds.begin(), cell.seeds.end(), 0);
    cell.fused_networks = std::getenv("PHNN_REFERENCE_NETWORKS") == nullptr;
    const std::uint64_t m0 = phnn::internal::gemm_multiply_adds();
    const double seconds = time_cell(cell, std::atoi(argv[5]));
    // The member GEMMs' multiply-adds of the whole cell (for FLOP bounds).
    std::printf("%.3f s %.0f MAC\n", seconds,
                static_cast<double>(phnn::internal::gemm_multiply_adds() - m0));
    return 0;
  }
  if (mode == "compare") {
    return compare(repeats, phnn::parse_size(argc > 3 ? argv[3] : "small"));
  }
  if (mode == "baseline") return baseline(repeats);
  if (mode == "precision") return precision(repeats);
  if (mode == "cell") return full_cell();
  if (mode == "general") return general(repeats);
  std::fprintf(stderr, "usage: bench_training stacked|baseline|cell [repeats]\n");
  return 2;
}
