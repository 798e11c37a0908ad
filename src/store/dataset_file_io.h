// src/store/dataset_file_io.h — data-set groups inside any HDF5 file (data
// files and the results file, which stores each system's data once).
#pragma once

#include <string>

#include "h5/h5file.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/store/dataset_file.h"

namespace phnn {
namespace internal {

/// Writes the three splits and the attributes under `group` ("/" or
/// "/data/duffing"). In a parallel file every rank calls it with the same data.
void write_system_data(h5::File& file, const std::string& group,
                       const SystemData& data);
SystemData read_system_data(const h5::File& file, const std::string& group);

/// The same for any system (format_version 2 of data-set files: state
/// names, units, the system file's text as attributes of `group`).
void write_ph_system_data(h5::File& file, const std::string& group, const PhSystemData& data);
PhSystemData read_ph_system_data(const h5::File& file, const std::string& group);

}  // namespace internal
}  // namespace phnn
