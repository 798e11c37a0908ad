// include/phnn/sweep/merge.h — shards of one sweep (`phnn sweep --shard I/N`,
// e.g. one per Slurm array task) merged into one results file. Serial.
#pragma once

#include <string>
#include <vector>

namespace phnn {

/// Which cells a shard trains: cells c (in Grid::cells order, largest
/// estimated cost first) with c % count == index, so shards get similar work.
struct Shard {
  int index = 0;
  int count = 1;

  /// "I/N" with 0 <= I < N <= kMaxShards; throws std::invalid_argument
  /// naming the text and the form otherwise.
  static Shard parse(const std::string& text);
  bool owns_cell(int cell) const { return cell % count == index; }
  /// `results/x.h5` -> `results/x.shard-I-of-N.h5` (".h5" appended if absent).
  std::string output_path(const std::string& sweep_output) const;
};

constexpr int kMaxShards = 100000;

/// Writes `out` (which must not exist) from `shards`: results files of the
/// same sweep text (equal sweep hash). Every run gets the result of the first
/// shard that has one; a run finished in two shards must be bitwise equal in
/// both (results depend only on configuration and seed), else it throws.
/// Every row is checked against its checksum (as `phnn verify` does) before
/// it is copied: a damaged shard row gives way to a good copy of the run in
/// another shard (named in the summary); with none, it throws naming the
/// shard, the row, "checksum mismatch" and the fix, and writes nothing.
/// Also copies the /data groups and every shard's provenance sessions. The
/// file is written under a scratch name and renamed when complete. Throws
/// std::invalid_argument for bad arguments (no shard, `out` exists or is a
/// shard, different sweeps) and std::runtime_error for I/O or conflicting
/// results, naming the files. Returns a summary, e.g.
///   "results/x.h5: 8 shards merged: 1200 of 1200 runs with results (1180 done, 20 diverged, 0 failed), 0 pending".
std::string merge_shards(const std::vector<std::string>& shards, const std::string& out,
                         const std::string& program_version);

}  // namespace phnn
