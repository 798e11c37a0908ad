// src/apps/cmd_train.cpp — `phnn train`: one cell, all its seeds stacked.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#include <torch/torch.h>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/provenance.h"
#include "apps/sweep_report.h"
#include "apps/train_cell_file.h"
#include "phnn/common/counted.h"
#include "phnn/common/closest_name.h"
#include "phnn/common/number_text.h"
#include "phnn/common/utc_time.h"
#include "phnn/config/study_defaults.h"
#include "phnn/config/training_settings.h"
#include "phnn/report/tables.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/store/output_path.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/systems/builtin_systems.h"
#include "phnn/systems/system_file.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace apps {
namespace {

std::string provenance_value(const Provenance& provenance, const std::string& key) {
  for (const auto& [k, v] : provenance) {
    if (k == key) return v;
  }
  return "";
}

// --out is checked before training, not after (store/output_path.h): a new
// results file, not an input, in a writable directory.
void require_new_output(const cli::Parser& parser) {
  std::vector<std::string> inputs;
  if (parser.has("system")) inputs.push_back(parser.get("system"));
  if (parser.has("data")) inputs.push_back(parser.get("data"));
  const std::string problem = output_problem("train", parser.get("out"), OutputKind::kResults, inputs);
  if (!problem.empty()) throw cli::UsageError{"phnn train: --out " + problem};
}

void declare_train_options(cli::Parser* parser) {
  parser->option("system", "harmonic | duffing | self-sustained | a system file (.toml); with "
                           "--data: optional (the data set names its system)");
  std::string models, integrators;
  for (const std::string& key : known_model_keys()) models += (models.empty() ? "" : ", ") + key;
  for (const std::string& name : kIntegratorNames.names()) {
    integrators += (integrators.empty() ? "" : " | ") + name;
  }
  parser->option("model",
                 "formulation-integrator as in sweep files: " + models +
                     " (the older `--model phnn-s --integrator dg` still works)",
                 "", true);
  parser->option("integrator", "old spelling: " + integrators + " with --model node|phnn-s|phnn-jr",
                 to_string(IntegratorKind::kRk2));
  parser->option("size", "small | medium | large", to_string(kDefaultSize));
  parser->option("n-train",
                 "training pairs (1..[data] num_train_max = " +
                     std::to_string(DatasetOptions().num_train_max) + ")",
                 std::to_string(kDefaultNTrain));
  parser->option("reg", "none | cn | sn | sr", to_string(kDefaultRegularizer));
  parser->option("seeds", "model seeds, e.g. 0-9 or 0,3,5",
                 "0-" + std::to_string(kDefaultSeedCount - 1));
  // The training settings with a flag (phnn/config/training_settings.h).
  const TrainerOptions defaults;
  for (const TrainingSetting& s : training_settings()) {
    if (*s.flag == '\0') continue;
    std::string help = s.doc;
    if (s.kind == TrainingSetting::Kind::kChoice) {
      std::string names;
      for (const std::string& n : s.choices()) names += (names.empty() ? "" : " | ") + n;
      help = names + ": " + help;
    }
    parser->option(s.flag, help, s.text(defaults));
  }
  parser->option("data", "read the data set from this file (`phnn data`) instead of generating it");
  parser->option("data-seed", "data-set seed when generating ([data] seed)",
                 std::to_string(DatasetOptions().data_seed));
  parser->option("damping", "c of z(w) = c w [N s/m] when generating",
                 shortest_number(OscillatorOptions().damping));
  parser->option("threads", "LibTorch intra-op threads", "1");
  parser->option("out", "also write the runs to this results file (readable by `phnn reduce`)");
  parser->flag("quiet", "no progress line");
}

// --model phnn-jr-rk2 (one name, as in sweep files), or the older
// --model phnn-jr [--integrator rk2], accepted with a note.
void parse_model_option(const cli::Parser& parser, CellSpec* cell) {
  const std::string name = parser.get("model");
  for (const std::string& integrator : kIntegratorNames.names()) {
    const std::string suffix = "-" + integrator;
    if (name.size() <= suffix.size() ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    cell->model = parse_model(name.substr(0, name.size() - suffix.size()));
    cell->integrator = parse_integrator(integrator);
    if (parser.has("integrator") && parser.get("integrator") != integrator) {
      throw cli::UsageError{"phnn train: --model " + name + " already names the integrator " +
                            integrator + "; drop --integrator " + parser.get("integrator")};
    }
    return;
  }
  try {
    cell->model = parse_model(name);
  } catch (const std::invalid_argument&) {
    const std::string near = closest_name(name, known_model_keys());
    throw cli::UsageError{"phnn train: --model \"" + name + "\"" +
                          (near.empty() ? "" : " (did you mean \"" + near + "\"?)") +
                          ": expected formulation-integrator as in sweep files, e.g. phnn-jr-rk2 "
                          "or node-rk4 (see --help)"};
  }
  cell->integrator = parse_integrator(parser.get("integrator"));
  std::cerr << "phnn train: note: --model " << name << " --integrator " << parser.get("integrator")
            << " is the older spelling of --model " << name << "-" << parser.get("integrator")
            << "\n";
}

CellSpec cell_from_options(const cli::Parser& parser) {
  CellSpec cell;
  parse_model_option(parser, &cell);
  cell.size = parse_size(parser.get("size"));
  cell.regularizer = parse_regularizer(parser.get("reg"));
  constexpr int kMax = std::numeric_limits<int>::max();
  cell.n_train = parser.get_int_in("n-train", 1, kMax);
  cell.seeds.clear();
  for (auto s : cli::parse_int_list("seeds", parser.get("seeds"))) cell.seeds.push_back(static_cast<int>(s));
  // The training settings with a flag; integers in the range of the
  // trainer's int counters: no silent wrap-around.
  for (const TrainingSetting& s : training_settings()) {
    if (*s.flag == '\0') continue;
    switch (s.kind) {
      case TrainingSetting::Kind::kReal:
        cell.training.*s.real = parser.get_double(s.flag);
        break;
      case TrainingSetting::Kind::kInteger:
        cell.training.*s.integer = parser.get_int_in(s.flag, s.min_integer, kMax);
        break;
      case TrainingSetting::Kind::kChoice:
        s.parse_choice(&cell.training, parser.get(s.flag));
        break;
    }
  }
  return cell;
}

// The options of a generated data set: --data-seed, and N_train checked.
DatasetOptions generation_options(const cli::Parser& parser, int n_train) {
  DatasetOptions options;
  const auto ds = parser.get_int("data-seed");
  if (ds < 0) throw cli::UsageError{"phnn train: --data-seed must be >= 0"};
  options.data_seed = static_cast<std::uint64_t>(ds);
  if (n_train < 1 || n_train > options.num_train_max) {
    throw cli::UsageError{"phnn train: --n-train = " + std::to_string(n_train) + " outside [1, " +
                          std::to_string(options.num_train_max) + "]"};
  }
  return options;
}

// The cost model's estimate of the cell (the one-cell sweep `text`, as
// `phnn sweep --dry-run` would give it), on stdout; a note on stderr when it
// is long for one command, which saves nothing until it ends.
void print_estimate(const std::string& text, const SystemFileReader& read) {
  const Grid grid = expand_grid(parse_sweep_text(text, "phnn train", read));
  const double seconds = grid.cells.front().estimated_cost_s;
  std::cout << "phnn train: estimated " << format_duration(seconds)
            << " on one core (the sweep cost model)" << std::endl;
  if (seconds > 600) {
    std::cerr << "phnn train: note: a long run for one command: nothing is saved until it ends; "
                 "a sweep file run by `phnn sweep` saves each cell's state and resumes"
              << std::endl;
  }
}

// A terminal gets one self-overwriting progress line, a log file a plain
// line per tenth of the run with the time (no carriage returns in logs).
ProgressCallback progress_printer(bool quiet) {
  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  return [quiet, terminal](const TrainProgress& p) {
    if (quiet) return;
    const int tenth = std::max(1, p.total_steps / 10);
    if (!terminal && p.step % tenth != 0 && p.step != p.total_steps) return;
    // No ETA before the first step (it would say 0 s).
    const std::string eta =
        p.step > 0 ? format_duration(p.elapsed_s / p.step * (p.total_steps - p.step)) : "--";
    std::fprintf(stderr, "%s  step %d/%d  best val %.3e  elapsed %s  ETA %s  %s%s",
                 terminal ? "\r" : "", p.step, p.total_steps, p.best_validation_loss,
                 format_duration(p.elapsed_s).c_str(), eta.c_str(),
                 terminal ? "" : ("(" + utc_now() + ")").c_str(),
                 terminal && p.step != p.total_steps ? "" : "\n");
  };
}

// One line per seed, then the reducer's statistics (numpy linear quartiles).
void print_cell_results(const CellSpec& cell, const std::vector<RunResult>& results) {
  std::vector<double> mses;
  double wall = 0.0;
  std::printf("%6s  %12s  %11s  %11s  %9s  %s\n", "seed", "MSE", "val(step 0)", "best val",
              "best step", "status");
  for (std::size_t e = 0; e < results.size(); ++e) {
    const RunResult& r = results[e];
    std::printf("%6d  %12.4e  %11.3e  %11.3e  %9d  %s %s\n", cell.seeds[e], r.mse,
                r.trace.empty() ? NAN : r.trace.front().validation_loss, r.best_validation_loss,
                r.best_step, to_string(r.status).c_str(), r.message.c_str());
    mses.push_back(r.mse);
    wall += r.wall_time_s;
  }
  const double q25 = quantile_linear(mses, 0.25), q50 = quantile_linear(mses, 0.5),
               q75 = quantile_linear(mses, 0.75);
  std::printf("median [IQR]: %.2e [%.2e]   parameters/member: %ld   wall time: %.1f s\n", q50,
              q75 - q25, results.empty() ? 0L : results[0].parameter_count, wall);
}

// The system and its data set. From --data: a built-in system's data say
// its physics (--damping is refused); a system file's data must have been
// made from the same text, and without --system the data set's own text is
// the system. Else generated for the cell's N_train from the system file,
// or the built-in system's shipped file with --damping.
struct TrainData {
  std::unique_ptr<PhSystem> system;
  PhSystemData data;
};

// --data without --system: the system entry the data set stands for — a
// built-in's name when its text is a built-in's, else "<name>.toml", a
// system file whose text the data set supplies.
std::string stored_system_entry(const PhSystemData& data, const std::string& path) {
  try {
    parse_system(data.system_name);
    builtin_physics(data.system_text, path + "@system_file");
    return data.system_name;
  } catch (const std::exception&) {
    return data.system_name + ".toml";
  }
}

TrainData read_train_data(const cli::Parser& parser, std::string* arg) {
  const std::string path = parser.get("data");
  const bool given = !arg->empty();
  TrainData d;
  d.data = read_ph_dataset_file(path);
  if (!given) *arg = stored_system_entry(d.data, path);
  const bool builtin = !is_system_file_argument(*arg);
  if (builtin && parser.has("damping")) {
    throw cli::UsageError{"phnn train: --damping with --data: the data set " + path +
                          " fixes the physics; drop --damping"};
  }
  if (builtin && d.data.system_name != *arg) {
    throw cli::UsageError{"phnn train: --data " + path + " holds system " + d.data.system_name +
                          ", not " + *arg + "; drop --system (the data set names its system)"};
  }
  if (builtin || !given) {  // the data set's own text is the system
    d.system = compile_system(d.data.system_text, path + "@system_file");
    return d;
  }
  d.system = load_system_file(system_file_path(*arg));
  if (d.data.system_text != d.system->source_text()) {
    throw cli::UsageError{"phnn train: --data " + path + " was made from another text of system " +
                          d.data.system_name + ", not from " + *arg +
                          "; drop --system (the data set holds its system's text), or regenerate "
                          "it with `phnn data --system " + *arg +
                          "` (for recordings, `phnn import ... --system " + *arg + "`)"};
  }
  return d;
}

// *arg: --system, or "" (then --data's own system, set here).
TrainData train_data(const cli::Parser& parser, std::string* arg_in, int n_train) {
  if (parser.has("data")) {
    TrainData d = read_train_data(parser, arg_in);
    if (static_cast<std::size_t>(n_train) > d.data.train.size())
      throw cli::UsageError{"phnn train: --n-train = " + std::to_string(n_train) + " exceeds the " +
                            std::to_string(d.data.train.size()) + " training pairs of --data " +
                            parser.get("data") + "; lower --n-train, or make a larger data set"};
    return d;
  }
  const std::string arg = *arg_in;
  if (arg.empty()) {
    throw cli::UsageError{"phnn train: give --system (a built-in name or a system file), or --data "
                          "FILE (a data set names its system)"};
  }
  const bool builtin = !is_system_file_argument(arg);
  const DatasetOptions options = generation_options(parser, n_train);
  TrainData d;
  if (builtin) {
    OscillatorOptions physics = OscillatorOptions::defaults(parse_system(arg));
    if (parser.has("damping")) physics.damping = parser.get_double("damping");
    d.system = builtin_system(physics, options);
  } else {
    if (parser.has("damping")) {
      throw cli::UsageError{"phnn train: --damping sets the built-in systems' c; a system file sets "
                            "its own under [parameters]: edit " + arg};
    }
    d.system = load_system_file(system_file_path(arg));
  }
  d.data = make_ph_system_data(*d.system, options, n_train);
  return d;
}

}  // namespace

int run_train(int argc, char** argv, int first) {
  cli::Parser parser("train",
                     "Trains one cell (all seeds of one configuration) as one stacked model,\n"
                     "then rolls every member out over the inference set (docs/METHOD.md §3-§5).\n\n"
                     "Example: phnn train --system duffing --model phnn-s-dg --seeds 0-9 --out cell.h5");
  declare_train_options(&parser);
  if (!parser.parse(argc, argv, first)) return 0;
  const CellSpec cell = cell_from_options(parser);
  if (parser.has("out")) require_new_output(parser);  // before any output or work
  torch::set_num_threads(parser.get_int_in("threads", 1, 4096));
  std::string arg = parser.get("system");
  if (!arg.empty() && !is_system_file_argument(arg)) parse_system(arg);  // unknown: an error before any work
  const Provenance provenance = session_provenance(MPI_COMM_NULL, argc, argv);
  const TrainData d = train_data(parser, &arg, cell.n_train);
  const bool builtin = !is_system_file_argument(arg);
  cell.validate(d.data);
  const PhSystem& system = *d.system;
  std::cout << "phnn train: " << system.name() << " (" << counted(system.n_x(), "state") << ", "
            << counted(system.n_w(), "port") << ", " << counted(system.n_u(), "input") << ") "
            << model_label(cell.model, cell.integrator) << " size=" << to_string(cell.size)
            << " n_train=" << cell.n_train << " reg=" << to_string(cell.regularizer)
            << " seeds=" << cell.seeds.size() << " steps=" << cell.training.steps << std::endl;
  // A system file's data set is at hand (read or generated above): supplied,
  // not to generate. Built-in systems are not read through the reader.
  SystemFileReader read;
  if (!builtin) {
    read = [&](const std::string&) {
      SystemFileText t{arg, system.source_text()};
      t.data_supplied = true;
      return t;
    };
  }
  const std::string text = cell_sweep_text(cell, d.data, arg);
  print_estimate(text, read);
  const auto results = train_cell(cell, d.data, system, progress_printer(parser.flag_set("quiet")));
  print_cell_results(cell, results);
  if (parser.has("out")) {
    write_cell_file(
        parser.get("out"), cell, text, read,
        [&](ResultsFile* file) { file->store_system_data(d.data.system_name, d.data, builtin ? "" : arg); },
        results, provenance, provenance_value(provenance, "started"));
    std::printf("runs written to %s\n", parser.get("out").c_str());
  }
  return 0;
}

}  // namespace apps
}  // namespace phnn
