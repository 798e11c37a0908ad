// src/store/dataset_file_io.h — data-set groups inside any HDF5 file (data
// files and the results file, which stores each system's data once).
#pragma once

#include <string>

#include "h5/h5file.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/data/ph_rows.h"

namespace phnn {
namespace internal {

/// The options every data-set version stores alike under `group`: seed,
/// timing, split sizes and the Newton tolerance (not the energy sampling,
/// which the versions read differently, nor version 1's energy intervals).
DatasetOptions read_dataset_timing(const h5::File& file, const std::string& group);

/// A format_version 1 group (a built-in system's 2-state layout, written
/// before 2026-11-28) as a data set of the built-in system's file.
PhSystemData read_version1_data(const h5::File& file, const std::string& group);

/// Writes the three splits and the attributes under `group` ("/" or
/// "/data/duffing"; format_version 2: state names, units, the system
/// file's text as attributes of `group`). In a parallel file every rank
/// calls it with the same data. read_ph_system_data reads either version.
/// Splits given as rows (when not null) are written instead of data's own
/// (data.train, data.validation, data.inference), with no copy.
struct SplitRows {
  const PhPairRows* train = nullptr;
  const PhPairRows* validation = nullptr;
  const PhInferenceRows* inference = nullptr;
};
void write_ph_system_data(h5::File& file, const std::string& group, const PhSystemData& data,
                          const SplitRows& rows = {});
PhSystemData read_ph_system_data(const h5::File& file, const std::string& group);

}  // namespace internal
}  // namespace phnn
