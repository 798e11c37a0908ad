// include/phnn/store/dataset_file.h — what identifies a data-set file
// ("phnn-dataset"; writing and reading: ph_dataset_file.h, which also reads
// the built-in systems' format_version 1 files written before 2026-11-28).
// Reads only the file it is given.
#pragma once

#include <string>

namespace phnn {

/// True if `path` is a regular HDF5 file whose root says format =
/// "phnn-dataset" (a file `phnn data` or `phnn import` wrote). Never throws.
bool is_dataset_file(const std::string& path);

}  // namespace phnn
