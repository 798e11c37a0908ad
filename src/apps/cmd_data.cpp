// src/apps/cmd_data.cpp — `phnn data`: a system's splits into one HDF5 file.
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <iostream>

#include "apps/cli.h"
#include "apps/commands.h"
#include "phnn/common/counted.h"
#include "phnn/common/number_text.h"
#include "phnn/data/measured.h"
#include "phnn/store/output_path.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/store/scratch_file.h"
#include "phnn/store/trajectory_files.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace apps {

namespace {

// --noise "0.01" (every state) or "0.01,0.02" (one per state).
NoiseOptions noise_options(const cli::Parser& parser, int n_x) {
  NoiseOptions o;
  o.relative = !parser.flag_set("noise-absolute");
  if (!parser.has("noise")) return o;
  const std::string text = parser.get("noise");
  for (const std::string& item : cli::split_commas(text)) {
    double v = 0;
    if (!cli::read_number(item, &v) || v < 0) {
      throw cli::UsageError{"phnn data: --noise " + text + ": \"" + item + "\" is not a number "
                            ">= 0; write one level for all states (0.01) or one per state "
                            "(0.01,0.02)"};
    }
    o.levels.push_back(v);
  }
  if (o.levels.size() == 1) o.levels.assign(static_cast<std::size_t>(n_x), o.levels[0]);
  if (static_cast<int>(o.levels.size()) != n_x) {
    throw cli::UsageError{"phnn data: --noise " + text + " gives " + std::to_string(o.levels.size()) +
                          " levels for " + std::to_string(n_x) + " states; give one, or one per state"};
  }
  return o;
}

int write_system_data(const std::unique_ptr<PhSystem>& system, const std::string& path,
                      const DatasetOptions& options, int n_train, const std::string& out,
                      const std::string& csv, const cli::Parser& parser,
                      std::chrono::steady_clock::time_point start) {
  PhSystemData data = make_ph_system_data(*system, options, n_train);
  add_measurement_noise(&data, system->rng_id(), noise_options(parser, system->n_x()));
  if (!csv.empty()) {
    // Written first: a failure leaves no data set that lacks its CSV.
    const TrajectoryColumns columns{system->state_names(), system->input_names()};
    const std::vector<MeasuredTrajectory> trajectories = generated_trajectories(*system, data);
    write_atomically(csv, "writing", [&](const std::string& scratch) {
      write_trajectory_csv(scratch, columns, trajectories,
                           "`phnn data --system " + path + " --data-seed " +
                               std::to_string(options.data_seed) + "`; import with `phnn import " +
                               csv + " --system " + path + " --num-validation " +
                               std::to_string(options.num_validation) + " --num-inference " +
                               std::to_string(options.num_inference) + " --data-seed " +
                               std::to_string(options.data_seed) + "`");
    });
  }
  write_atomically(out, "writing", [&](const std::string& scratch) { write_ph_dataset_file(scratch, data); });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "phnn data: " << system->name() << " (" << path << ", "
            << counted(system->n_x(), "state") << ", " << counted(system->n_w(), "port") << ", "
            << counted(system->n_u(), "input") << "): "
            << data.train.size() << " train pairs, " << data.validation.size()
            << " validation pairs, " << data.inference.size() << " inference trajectories x "
            << (data.inference.size() ? data.inference.states[0].size() : 0) << " samples -> "
            << out << " (" << seconds << " s)\n";
  if (!data.noise.empty()) std::cout << "phnn data: noise: " << data.noise << "\n";
  return 0;
}

// --csv: not with --noise, never over --out or the system file.
void check_csv_option(const cli::Parser& parser, const std::string& csv, const std::string& out,
                      const std::string& system_arg) {
  if (parser.has("noise") && parser.has("csv")) {
    throw cli::UsageError{"phnn data: --csv writes the clean trajectories, --noise perturbs only "
                          "the pairs: use one of them (add noise to a recording before importing it)"};
  }
  if (parser.has("csv")) {
    const std::string bad = output_problem("data", csv, OutputKind::kTrajectoryCsv, {system_arg, out});
    if (!bad.empty()) throw cli::UsageError{"phnn data: --csv " + bad};
    // Neither exists yet, so compare the paths themselves.
    if (std::filesystem::weakly_canonical(csv) == std::filesystem::weakly_canonical(out)) {
      throw cli::UsageError{"phnn data: --csv and --out are the same file (" + csv +
                            "); give the trajectories' CSV its own name, e.g. " + out + ".csv"};
    }
  }
}

}  // namespace

int run_data(int argc, char** argv, int first) {
  cli::Parser parser("data",
                     "Generates the train / validation / inference splits of one "
                     "system (docs/METHOD.md §2)\nwith the Gonzalez discrete gradient and "
                     "writes them to an HDF5 file.\n\n"
                     "Example: phnn data --system duffing --n-train 100 --out duffing.h5 --csv duffing.csv");
  parser.option("system", "harmonic | duffing | self-sustained | a system file (.toml)", "", true);
  parser.option("out", "output HDF5 file", "", true);
  const DatasetOptions data_defaults;
  const OscillatorOptions physics_defaults;
  parser.option("n-train", "training pairs to generate (<= [data] num_train_max)",
                std::to_string(data_defaults.num_train_max));
  parser.option("data-seed", "seed of the counter-based RNG ([data] seed)",
                std::to_string(data_defaults.data_seed));
  parser.option("damping", "c of z(w) = c w [N s/m] (harmonic, duffing)",
                shortest_number(physics_defaults.damping));
  parser.option("mass", "m [kg]", shortest_number(physics_defaults.mass));
  parser.option("csv", "also write the trajectories behind the splits to this CSV "
                       "(`phnn import`'s format)");
  parser.option("noise", "measurement noise on the training and validation pairs: one level for "
                         "all states (0.01) or one per state (0.01,0.02), relative to each "
                         "state's spread");
  parser.flag("noise-absolute", "--noise levels are absolute standard deviations");
  if (!parser.parse(argc, argv, first)) return 0;

  const std::string system_arg = parser.get("system");
  const bool from_file = is_system_file_argument(system_arg);
  if (from_file && (parser.has("damping") || parser.has("mass"))) {
    throw cli::UsageError{"phnn data: --damping and --mass set the built-in systems' parameters; "
                          "a system file sets its own under [parameters]: edit " + system_arg};
  }
  OscillatorOptions physics;
  if (!from_file) {
    physics = OscillatorOptions::defaults(parse_system(system_arg));
    if (parser.has("damping")) physics.damping = parser.get_double("damping");
    physics.mass = parser.get_double("mass");
    physics.validate();
  }
  DatasetOptions options;
  const std::int64_t seed = parser.get_int("data-seed");
  if (seed < 0) throw cli::UsageError{"phnn data: --data-seed = " + std::to_string(seed) + " must be >= 0"};
  options.data_seed = static_cast<std::uint64_t>(seed);
  const std::int64_t n_train = parser.get_int("n-train");
  if (n_train < 1 || n_train > options.num_train_max) {
    throw cli::UsageError{"phnn data: --n-train = " + std::to_string(n_train) +
                          " outside [1, " + std::to_string(options.num_train_max) + "]"};
  }
  const std::string out = parser.get("out");
  const std::string problem = output_problem("data", out, OutputKind::kDataSet, {system_arg});
  if (!problem.empty()) throw cli::UsageError{"phnn data: --out " + problem};
  const std::string csv = parser.get("csv");
  if (parser.flag_set("noise-absolute") && !parser.has("noise")) {
    throw cli::UsageError{"phnn data: --noise-absolute without --noise; give the levels"};
  }
  check_csv_option(parser, csv, out, system_arg);
  const auto start = std::chrono::steady_clock::now();
  const std::unique_ptr<PhSystem> system = from_file ? load_system_file(system_file_path(system_arg))
                                                     : builtin_system(physics, options);
  return write_system_data(system, system_arg, options, static_cast<int>(n_train), out, csv, parser,
                           start);
}

}  // namespace apps
}  // namespace phnn
