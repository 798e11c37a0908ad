// bench/profile_step.cpp — per-operator profile of training steps (chrome
// trace JSON from the LibTorch autograd profiler), for finding hot spots.
//   profile_step MODEL INTEGRATOR MEMBERS STEPS OUT.json [float32]
#include <cstdlib>
#include <string>

#include <torch/csrc/autograd/profiler_legacy.h>
#include <torch/torch.h>

#include "phnn/data/ph_dataset.h"
#include "phnn/training/trainer.h"

int main(int argc, char** argv) {
  if (argc < 6) return 2;
  torch::set_num_threads(1);
  phnn::DatasetOptions options;
  options.num_validation = 64;
  options.num_inference = 1;
  const auto system =
      phnn::builtin_system(phnn::OscillatorOptions::defaults(phnn::SystemKind::kDuffing), options);
  const auto data = phnn::make_ph_system_data(*system, options, 64);
  phnn::CellSpec cell;
  cell.model = phnn::parse_model(argv[1]);
  cell.integrator = phnn::parse_integrator(argv[2]);
  cell.n_train = 64;
  cell.seeds.clear();
  for (int s = 0; s < std::atoi(argv[3]); ++s) cell.seeds.push_back(s);
  cell.training.steps = std::atoi(argv[4]);
  cell.training.eval_every = 1000000;
  if (argc > 6 && std::string(argv[6]) == "float32") cell.training.precision = phnn::Precision::kFloat32;
  torch::autograd::profiler::RecordProfile guard(argv[5]);
  phnn::train_cell(cell, data, *system);
  return 0;
}
