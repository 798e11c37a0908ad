// src/apps/cmd_import.cpp — `phnn import`: recorded trajectories (CSV or
// HDF5) into a data-set file, split as docs/METHOD.md "Measured data" says.
#include <chrono>
#include <iostream>

#include "apps/cli.h"
#include "apps/commands.h"
#include "phnn/common/counted.h"
#include "phnn/data/measured.h"
#include "phnn/store/output_path.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/store/scratch_file.h"
#include "phnn/store/trajectory_files.h"
#include "phnn/systems/measurement_map.h"
#include "phnn/systems/ph_system.h"

namespace phnn {
namespace apps {

namespace {

// --blocks "0.6,0.2": the training and validation shares of each recording.
void parse_blocks(const std::string& text, ImportOptions* o) {
  const std::vector<std::string> shares = cli::split_commas(text);
  const bool numbers = shares.size() == 2 && cli::read_number(shares[0], &o->train_fraction) &&
                       cli::read_number(shares[1], &o->validation_fraction);
  if (!numbers || !(o->train_fraction > 0) || !(o->validation_fraction > 0) ||
      !(o->train_fraction + o->validation_fraction < 1)) {
    throw cli::UsageError{"phnn import: --blocks " + text + ": give the training and validation "
                          "shares of each recording, both > 0 with a sum < 1 (the inference block "
                          "is the rest), e.g. --blocks 0.6,0.2"};
  }
}

ImportOptions import_options(const cli::Parser& parser) {
  ImportOptions o;
  const std::string split = parser.get("split");
  if (!kImportSplitNames.find(split, &o.split)) {
    throw cli::UsageError{"phnn import: --split " + split + ": give blocks (a few long recordings, "
                          "cut in time) or trajectories (one pair per trajectory)"};
  }
  const bool blocks = o.split == ImportSplit::kBlocks;
  for (const char* name : {"pair-window", "split-seed"}) {
    if (blocks && parser.has(name)) {
      throw cli::UsageError{std::string("phnn import: --") + name + " belongs to --split "
                            "trajectories; blocks use every pair of a block, in time order"};
    }
  }
  for (const char* name : {"blocks", "window"}) {
    if (!blocks && parser.has(name)) {
      throw cli::UsageError{std::string("phnn import: --") + name + " belongs to --split blocks"};
    }
  }
  parse_blocks(parser.get("blocks"), &o);
  o.window = parser.get_double_in("window", 0.0, 1e12);
  o.data_seed = static_cast<std::uint64_t>(parser.get_int_in("data-seed", 0, 2147483647));
  o.num_validation = parser.get_int_in("num-validation", 1, 100000000);
  o.num_inference = parser.get_int_in("num-inference", 1, 100000000);
  o.pair_window = parser.get_double_in("pair-window", 0.0, 1e12);
  o.sample_rate = parser.get_double_in("sample-rate", 0.0, 1e12);
  o.split_seed = parser.has("split-seed") ? parser.get_int_in("split-seed", 0, 2147483647) : -1;
  return o;
}

}  // namespace

int run_import(int argc, char** argv, int first) {
  cli::Parser parser("import",
                     "Reads recorded trajectories (CSV: trajectory,t,<states>,<inputs>; or HDF5:\n"
                     "/trajectories/<id>/{t,x,u}) and writes a data-set file that `phnn train\n"
                     "--data` and sweeps read (docs/METHOD.md, \"Measured data\"). --split blocks\n"
                     "(a few long recordings): each recording is cut in time into a training, a\n"
                     "validation and an inference block; every pair inside a block is a pair, and\n"
                     "inference windows lie in the last block. --split trajectories (many short\n"
                     "ones, as `phnn data --csv` writes): one pair per trajectory, each trajectory\n"
                     "in one role.\n\n"
                     "Example: phnn import rec.csv --system pendulum.toml --blocks 0.6,0.2 --window 10 --out rec.h5");
  parser.positional_rest("FILE", "CSV or HDF5 trajectory files (their trajectories are joined)");
  parser.option("system", "a system file (.toml) or built-in name: the state and input names", "",
                true);
  parser.option("out", "output data-set file (HDF5)", "", true);
  parser.option("split", "blocks | trajectories (see above)", "blocks");
  parser.option("blocks", "blocks: training and validation shares of each recording's samples "
                          "(inference: the rest)", "0.6,0.2");
  parser.option("window", "blocks: inference windows of this duration [s]; 0: the whole block", "0");
  parser.option("num-validation", "trajectories: trajectories for validation pairs; blocks: at most "
                                  "this many validation pairs", "2500");
  parser.option("num-inference", "trajectories: trajectories for inference (the last ones after "
                                 "the split); blocks: at most this many windows", "100");
  parser.option("pair-window", "trajectories: draw pairs with t_n+1 - t_0 <= this [s]; 0: anywhere", "0");
  parser.option("ignore-columns", "columns of the files to skip, e.g. temperature,t_ms (the system "
                                  "file's [measurement] ignore lists more)");
  parser.option("sample-rate", "sampling rate [Hz] (checked against t); 0: from t", "0");
  parser.option("data-seed", "seed of the pair draws (as `phnn data --data-seed`)", "0");
  parser.option("split-seed", "trajectories: shuffle them by this seed before the split "
                              "(default: in the order of their ids)");
  if (!parser.parse(argc, argv, first)) return 0;

  const auto start = std::chrono::steady_clock::now();
  if (!is_system_file_argument(parser.get("system"))) {
    throw cli::UsageError{"phnn import: --system " + parser.get("system") + ": give a system file "
                          "(the built-in systems are sweeps/systems/harmonic.toml, duffing.toml "
                          "and self-sustained.toml)"};
  }
  const std::unique_ptr<PhSystem> system = make_system(parser.get("system"));
  const ImportOptions options = import_options(parser);
  const std::string out = parser.get("out");
  std::vector<std::string> inputs = parser.rest();
  inputs.push_back(parser.get("system"));
  const std::string problem = output_problem("import", out, OutputKind::kDataSet, inputs);
  if (!problem.empty()) throw cli::UsageError{"phnn import: --out " + problem};

  const MeasurementMap measurement =
      MeasurementMap::of_system_text(system->source_text(), parser.get("system"));
  TrajectoryColumns columns{measurement.recorded(), system->input_names(), measurement.ignored()};
  if (parser.has("ignore-columns")) {
    for (const std::string& name : cli::split_commas(parser.get("ignore-columns"))) {
      if (!name.empty()) columns.ignore.push_back(name);
    }
  }
  std::string summary;
  if (!measurement.identity()) summary += "states from [measurement]: " + measurement.describe() + "\n";
  // Two passes over the files (docs/METHOD.md "Measured data"): memory
  // follows the data set written, not the recordings.
  MeasuredDataSet set;
  try {
    set = split_measured_stream(*system, recorded_trajectories(parser.rest(), columns, measurement),
                                options, &summary);
  } catch (const MeasuredDataError& e) {
    throw cli::UsageError{std::string("phnn import: ") + e.what()};  // bad input: exit 2
  }
  write_atomically(out, "writing", [&](const std::string& path) {
    write_ph_dataset_file(path, set.data, set.train, set.validation, set.inference);
  });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const bool blocks = options.split == ImportSplit::kBlocks;
  std::cout << summary << "phnn import: " << system->name() << ": "
            << counted(static_cast<long long>(set.train.size()), "training pair") << ", "
            << counted(static_cast<long long>(set.validation.size()), "validation pair") << ", "
            << (blocks ? counted(static_cast<long long>(set.inference.size()), "inference window")
                       : counted(static_cast<long long>(set.inference.size()), "inference trajectory",
                                 "inference trajectories"))
            << " -> " << out << " (" << seconds << " s)\n";
  return 0;
}

}  // namespace apps
}  // namespace phnn
