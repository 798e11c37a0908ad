// include/phnn/store/ph_dataset_file.h — data-set files of any PhSystem
// (format_version 2 of "phnn-dataset"; docs/RESULTS_FORMAT.md, "Data-set
// files"): states of n_x components, inputs of n_u, the state names and
// units, and the system file's text, so the data say what made them.
// Writes only the file it is given; reads data-set files.
#pragma once

#include <string>

#include "phnn/data/ph_dataset.h"

namespace phnn {

/// Writes `data` to a new HDF5 file (replaces `path`).
void write_ph_dataset_file(const std::string& path, const PhSystemData& data);

/// Reads a data-set file of either version (a built-in system's version-1
/// file comes back with state names q, p and input u). Throws
/// std::runtime_error naming the file when it is not a phnn data set.
PhSystemData read_ph_dataset_file(const std::string& path);

}  // namespace phnn
