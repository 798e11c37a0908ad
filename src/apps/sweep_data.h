// src/apps/sweep_data.h — the data sets a sweep trains on, one per system
// (a built-in system's shipped file, a system file, a `data` file), with the
// compiled system its models take S and J from. Made on demand, the same on
// every rank (deterministic); stored once in the results file's /data.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "phnn/data/ph_dataset.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/systems/ph_system.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace apps {

class SweepDataSets {
 public:
  /// Keeps references to `spec` and `grid`, which must outlive it.
  SweepDataSets(const SweepSpec& spec, const Grid& grid) : spec_(spec), grid_(grid) {}

  /// Makes the data set of `system_name` (RunConfig::system_name()) with
  /// as many training pairs as its largest n_train, unless made already.
  /// Throws what data generation throws (a system file's Newton failure;
  /// GenerationStopped when the stop set below says stop).
  void make(const std::string& system_name);
  /// Asked between generated trajectories (a stop signal).
  void set_stop(GenerationStop stop) { stop_ = std::move(stop); }
  /// Collective: stores the data set under /data/<system_name> (make first).
  void store(const std::string& system_name, ResultsFile* results) const;
  /// "" when the data set of `system_name` (make first) has the bits of the
  /// one stored in `results` (its validation and inference splits, and the
  /// training pairs both hold), else what differs: a resumed sweep
  /// regenerates its data, and a data generator that changed (another
  /// phnn version, another libm for sin/exp) must not mix its runs with
  /// the file's.
  std::string stored_data_problem(const std::string& system_name,
                                  const ResultsFile& results) const;
  /// Trains one cell of `system_name` (make first): train_cell on its data.
  std::vector<RunResult> train(const CellSpec& cell, const std::string& system_name,
                               const ProgressCallback& progress,
                               const CellCheckpointing* checkpointing = nullptr) const;

 private:
  struct DataSet {
    PhSystemData data;
    std::unique_ptr<PhSystem> system;
  };
  const DataSet& at(const std::string& system_name) const;
  GenerationStop stop_;

  const SweepSpec& spec_;
  const Grid& grid_;
  std::map<std::string, DataSet> data_;
};

}  // namespace apps
}  // namespace phnn
