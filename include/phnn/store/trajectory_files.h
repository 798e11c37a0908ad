// include/phnn/store/trajectory_files.h — recorded trajectories in CSV and
// HDF5 files (docs/DATASET_FORMAT.md, "Trajectory files"): the readers of
// `phnn import` and the CSV writer of `phnn data --csv`. Reads the files it
// is given; writes only the file it is given.
#pragma once

#include <string>
#include <vector>

#include "phnn/data/measured.h"
#include "phnn/systems/measurement_map.h"

namespace phnn {

/// The column names a trajectory file must hold: the system's state and
/// input names.
struct TrajectoryColumns {
  /// `states`: the recorded columns that make the states (a system's states,
  /// or MeasurementMap::recorded()); `ignore`: columns a file may hold that
  /// are skipped.
  std::vector<std::string> states, inputs;
  std::vector<std::string> ignore = {};
};

/// CSV, one row per sample: a header naming the columns `trajectory`, `t`,
/// every state and every input (in any order, each once, nothing else),
/// then numbers (`trajectory` a non-negative integer; rows of one
/// trajectory contiguous, in increasing t). Blank lines and lines starting
/// with '#' are skipped; CRLF line ends are accepted. Throws
/// MeasuredDataError "FILE:LINE: what; the fix" (missing, extra or repeated
/// column, a ragged row, a field that is not a number, NaN or infinity, a
/// trajectory whose rows are split, an empty file).
std::vector<MeasuredTrajectory> read_trajectory_csv(const std::string& path,
                                                    const TrajectoryColumns& columns);
/// The same, one trajectory at a time: visit(m) once its last row is read
/// (`m` is reused for the next: copy what you keep), so a file costs its
/// longest trajectory, not its size. The trajectories before a malformed
/// row are visited before the error is thrown.
void for_each_csv_trajectory(const std::string& path, const TrajectoryColumns& columns,
                             const TrajectoryVisitor& visit);

/// The first line of every trajectory CSV phnn writes starts with this (the
/// readers skip it as a comment): only such files are ever replaced.
constexpr const char* kTrajectoryCsvMarker = "# phnn trajectories";
/// True when `path`'s first line starts with kTrajectoryCsvMarker.
bool is_phnn_trajectory_csv(const std::string& path);

/// Writes `trajectories` as CSV: the marker line (with `note` after it),
/// the header `trajectory,t,<states>,<inputs>`, then one row per sample,
/// values as the shortest text that reads back to the same double.
void write_trajectory_csv(const std::string& path, const TrajectoryColumns& columns,
                          const std::vector<MeasuredTrajectory>& trajectories,
                          const std::string& note = "");

/// HDF5: a group `/trajectories` with one group per trajectory, named by its
/// id (a non-negative integer), holding `t` (N), `x` (N x n_x, columns in
/// the order of the system's states) and `u` (N x n_u; absent when n_u = 0).
/// Optional string attributes `state_names` and `input_names` on
/// `/trajectories` (comma-separated) are checked against the system's.
/// Throws MeasuredDataError naming "FILE:/trajectories/ID" and the fix.
std::vector<MeasuredTrajectory> read_trajectory_h5(const std::string& path,
                                                   const TrajectoryColumns& columns);
/// The same, one trajectory (group) at a time.
void for_each_h5_trajectory(const std::string& path, const TrajectoryColumns& columns,
                            const TrajectoryVisitor& visit);

/// What `phnn import` splits: the trajectories of `files` (each HDF5 or
/// CSV by its content) one at a time, file after file, with the states
/// [measurement] computes (`map`, which must outlive the source; columns:
/// map.recorded() as the states). A pass reads the files anew, so a source
/// holds one trajectory, not the files. Errors as the readers' and
/// apply_measurement's, in the order of reading every file first and then
/// computing the states: a [measurement] error is thrown at the end of the
/// pass. A CSV file read whole once is not checked again for trajectories
/// whose rows are split (16 bytes a trajectory): split_measured_stream
/// checks each later pass against the first.
TrajectorySource recorded_trajectories(const std::vector<std::string>& files,
                                       const TrajectoryColumns& columns, const MeasurementMap& map);

}  // namespace phnn
