// include/phnn/store/ph_dataset_file.h — data-set files of any PhSystem
// (format_version 2 of "phnn-dataset"; docs/RESULTS_FORMAT.md, "Data-set
// files"): states of n_x components, inputs of n_u, the state names and
// units, and the system file's text, so the data say what made them.
// Writes only the file it is given; reads data-set files.
#pragma once

#include <string>

#include "phnn/config/system_file_text.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/data/ph_rows.h"

namespace phnn {

/// Writes `data` to a new HDF5 file (replaces `path`).
void write_ph_dataset_file(const std::string& path, const PhSystemData& data);
/// The same file for a data set whose splits are given as rows (`data`
/// holds the rest and no pairs or inference trajectories): what `phnn
/// import` writes, with no object per pair or sample and no copy.
void write_ph_dataset_file(const std::string& path, const PhSystemData& data, const PhPairRows& train,
                           const PhPairRows& validation, const PhInferenceRows& inference);

/// hex64(fnv1a64(...)) (the run ids' hash) over what training and inference
/// read: the system text, the state and input names, every pair's x,
/// x_next, u and every inference state and input (doubles by their bytes),
/// and the steps. Two files with the same contents have the same checksum,
/// whatever their other attributes: a data-set file's identity in sweeps.
std::string data_set_checksum(const PhSystemData& data);

/// What a sweep needs of a data-set file named in `data`: its checksum, its
/// training pairs, its inference trajectories and the samples of the
/// longest (the results layout's), set in `text`.
void describe_data_file(const PhSystemData& data, SystemFileText* text);

/// Reads a data-set file of either version (a built-in system's version-1
/// file comes back with state names q, p and input u). Throws
/// std::runtime_error naming the file when it is not a phnn data set.
PhSystemData read_ph_dataset_file(const std::string& path);

}  // namespace phnn
