// src/apps/phnn.cpp — the single `phnn` executable: phnn <command> [options].
#include <csignal>
#include <cstring>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/early_signals.h"
#include "apps/provenance.h"
#include "phnn/common/closest_name.h"

namespace {

struct Command {
  const char* name;
  int (*run)(int argc, char** argv, int first);
};

// Each parses its own options (apps/cli.h) from argv[2] on.
const Command kCommands[] = {
    {"data", phnn::apps::run_data},
    {"import", phnn::apps::run_import},
#ifdef PHNN_HAVE_TRAIN
    {"train", phnn::apps::run_train},
#endif
#ifdef PHNN_HAVE_SWEEP
    {"sweep", phnn::apps::run_sweep}, {"reduce", phnn::apps::run_reduce},
    {"merge", phnn::apps::run_merge}, {"eval", phnn::apps::run_eval},
    {"verify", phnn::apps::run_verify},
#endif
};

// "phnn: unknown command "trian" (did you mean train?); expected one of: ..."
std::string unknown_command(const std::string& command) {
  std::vector<std::string> names = {"--help", "--version"};
  std::string list;
  for (const Command& c : kCommands) {
    names.push_back(c.name);
    list += (list.empty() ? "" : ", ") + std::string(c.name);
  }
  const std::string best = phnn::closest_name(command, names);
  return "phnn: unknown command \"" + command + "\"" +
         (best.empty() ? "" : " (did you mean " + best + "?)") + "; expected one of: " + list;
}

const char* kUsage =
    "usage: phnn <command> [options]\n\n"
    "Port-Hamiltonian neural networks for controlled oscillators: data, training\n"
    "and distributed sweeps (paper: \"Controlled oscillation modeling using\n"
    "port-Hamiltonian neural networks\").\n\n"
    "commands:\n"
    "  data     generate a system's data splits into an HDF5 file\n"
    "  import   read recorded trajectories (CSV, HDF5) into a data-set file\n"
    "  train    train one cell (all seeds of one configuration)\n"
    "  sweep    run a sweep file over MPI ranks into one HDF5 results file\n"
    "  reduce   print the paper's median [IQR] tables from a results file\n"
    "  merge    merge the shard results files of one sweep into one\n"
    "  eval     reload one run from its stored weights and evaluate it again\n"
    "  verify   check a results file's structure and every row's checksum\n\n"
    "`phnn <command> --help` lists each command's options; `phnn --version` prints\n"
    "the version, git commit and library versions.\n";

}  // namespace

int main(int argc, char** argv) {
  // SIGTERM/SIGUSR1 are held from the process's start (apps/early_signals.h).
  // A file-size limit (ulimit -f) then fails the write with EFBIG, reported
  // like a full disk, instead of killing the process without a word.
  std::signal(SIGXFSZ, SIG_IGN);
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::cout << kUsage;
    return argc < 2 ? phnn::cli::kUsageError : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::cout << phnn::apps::version_text();
    return 0;
  }
  const std::string command = argv[1];
  // Only a sweep stops gracefully; the others end by the signal, as usual.
  if (command != "sweep") phnn::apps::restore_default_stop_signals();
  try {
    for (const Command& c : kCommands) {
      if (command == c.name) return c.run(argc, argv, 2);
    }
    std::cerr << unknown_command(command) << "\n";
    return phnn::cli::kUsageError;
  } catch (const phnn::cli::UsageError& e) {
    std::cerr << e.message << "\n";
    return phnn::cli::kUsageError;
  } catch (const std::invalid_argument& e) {
    std::cerr << phnn::cli::with_prefix("phnn " + command + ": ", e.what()) << "\n";
    return phnn::cli::kUsageError;
  } catch (const std::exception& e) {
    const std::string prefix = "phnn " + command + ": ";
    const std::string text = e.what();
    // Said once: a message that names the command already keeps its words.
    std::cerr << (text.compare(0, prefix.size(), prefix) == 0 ? text : prefix + "error: " + text)
              << "\n";
    return 1;
  }
}
