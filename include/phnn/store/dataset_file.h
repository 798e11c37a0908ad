// include/phnn/store/dataset_file.h — data-set files of the built-in systems
// (format_version 1, docs/DATASET_FORMAT.md): SystemData to and from HDF5.
// Reads and writes only the file it is given.
#pragma once

#include <string>

#include "phnn/data/dataset.h"

namespace phnn {

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
