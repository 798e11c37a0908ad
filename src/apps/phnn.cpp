// src/apps/phnn.cpp — the single `phnn` executable: phnn <command> [options].
#include <cstring>
#include <exception>
#include <iostream>
#include <string>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/provenance.h"

namespace {

const char* kUsage =
    "usage: phnn <command> [options]\n\n"
    "Port-Hamiltonian neural networks for controlled oscillators: data, training\n"
    "and distributed sweeps (paper: \"Controlled oscillation modeling using\n"
    "port-Hamiltonian neural networks\").\n\n"
    "commands:\n"
    "  data     generate a system's data splits into an HDF5 file\n"
    "  train    train one cell (all seeds of one configuration)\n"
    "  sweep    run a sweep file over MPI ranks into one HDF5 results file\n"
    "  reduce   print the paper's median [IQR] tables from a results file\n"
    "  merge    merge the shard results files of one sweep into one\n"
    "  eval     reload one run from its stored weights and evaluate it again\n\n"
    "`phnn <command> --help` lists each command's options; `phnn --version` prints\n"
    "the version, git commit and library versions.\n";

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::cout << kUsage;
    return argc < 2 ? phnn::cli::kUsageError : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::cout << phnn::apps::version_text();
    return 0;
  }
  const std::string command = argv[1];
  try {
    if (command == "data") return phnn::apps::run_data(argc, argv, 2);
#ifdef PHNN_HAVE_TRAIN
    if (command == "train") return phnn::apps::run_train(argc, argv, 2);
#endif
#ifdef PHNN_HAVE_SWEEP
    if (command == "sweep") return phnn::apps::run_sweep(argc, argv, 2);
    if (command == "reduce") return phnn::apps::run_reduce(argc, argv, 2);
    if (command == "merge") return phnn::apps::run_merge(argc, argv, 2);
    if (command == "eval") return phnn::apps::run_eval(argc, argv, 2);
#endif
    std::cerr << "phnn: unknown command \"" << command
              << "\"; expected one of: data, train, sweep, reduce, merge, eval\n";
    return phnn::cli::kUsageError;
  } catch (const phnn::cli::UsageError& e) {
    std::cerr << e.message << "\n";
    return phnn::cli::kUsageError;
  } catch (const std::invalid_argument& e) {
    std::cerr << "phnn " << command << ": " << e.what() << "\n";
    return phnn::cli::kUsageError;
  } catch (const std::exception& e) {
    std::cerr << "phnn " << command << ": error: " << e.what() << "\n";
    return 1;
  }
}
