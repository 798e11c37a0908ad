// include/phnn/data/dataset_file.h
#pragma once

#include <string>

#include "phnn/data/dataset.h"

namespace phnn {

/// Everything one system contributes to an experiment: the training pairs
/// (first n_train of them are used by a run), validation pairs and inference
/// trajectories (docs/METHOD.md §2).
struct SystemData {
  OscillatorOptions system;
  DatasetOptions options;
  PairSet train;
  PairSet validation;
  InferenceSet inference;
};

/// Generates a system's splits. `num_train` pairs of the train split (at most
/// options.num_train_max) are generated; only what is asked is computed.
SystemData make_system_data(const OscillatorOptions& system,
                            const DatasetOptions& options, int num_train);

/// Writes `data` to a new HDF5 file (layout in docs/DATASET_FORMAT.md): groups
/// train/, validation/, inference/ with datasets x, x_next, u, trajectory,
/// position (pairs) and u, trajectory, states (inference); parameters and
/// units as attributes on the root.
void write_dataset_file(const std::string& path, const SystemData& data);

/// True if `path` is a regular HDF5 file whose root says format =
/// "phnn-dataset" (a file write_dataset_file wrote). Never throws.
bool is_dataset_file(const std::string& path);

/// Reads a file written by write_dataset_file; throws std::runtime_error
/// naming the file if it is missing, not HDF5, or not a phnn data set.
SystemData read_dataset_file(const std::string& path);

}  // namespace phnn
