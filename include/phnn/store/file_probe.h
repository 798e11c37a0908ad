// include/phnn/store/file_probe.h — what the store can tell about a file
// before anyone opens it as ours, and which HDF5 it is built on: the answers
// the sweep's output check and the provenance need, without HDF5 above the
// store.
#pragma once

#include <exception>
#include <string>

namespace phnn {

/// The root attribute "format" of the HDF5 file at `path` ("(missing)" when
/// it has none; ResultsFile::kFormat for a results file). Throws
/// std::runtime_error when HDF5 cannot open it (not HDF5, damaged, no access).
std::string hdf5_format_attribute(const std::string& path);

/// True when `e` came from HDF5 (a file damaged or cut short), false for the
/// store's own refusals (another format version, a missing column, ...).
bool is_hdf5_error(const std::exception& e);

/// The HDF5 library's version, e.g. "1.10.8".
std::string hdf5_library_version();

}  // namespace phnn
