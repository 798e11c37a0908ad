// src/store/results_file_checks.cpp — the row checksums of a results file
// by its rule (docs/RESULTS_FORMAT.md, "Checksums"), the checks built on
// them (row_damage, damaged_rows), the file's structural checks, and making
// a row pending again. File and /data digests: results_file_digest.cpp.
#include <set>

#include "phnn/config/run_config.h"  // fnv1a64
#include "phnn/store/journal.h"
#include "store/results_file_internal.h"

namespace phnn {

using namespace results_io;

namespace {

// 0 is stored for "no checksum yet".
std::uint64_t nonzero(std::uint64_t hash) { return hash == 0 ? 1 : hash; }

}  // namespace

// Rule 1 (files without checksum_version): FNV-1a 64 of the row's id,
// canonical configuration, seed and result as read_run returns it without
// its run times (the journal's encoding: every double bit for bit).
//
// Rule 2: FNV-1a 64 of, for every dataset of /runs but checksum in order
// of its path, the path, a NUL and the row's stored bytes (all 64 bits of
// each integer, strings with their padding, arrays padding included), then
// "/weights", a NUL and the row's weights as stored.
std::uint64_t ResultsFile::row_checksum(int row) const {
  const Impl& impl = *impl_;
  const auto at = static_cast<std::uint64_t>(row);
  if (impl.checksum_version == 1) {
    const std::string id = impl.strings_at(kId, at);
    RunResult r = read_run(row);
    r.started_utc.clear();
    r.finished_utc.clear();
    return nonzero(fnv1a64(id + "\n" + impl.strings_at(kCanonical, at) + "\n" +
                           std::to_string(impl.ints(kSeed, at, 1).at(0)) + "\n" +
                           internal::encode_journal_record(id, r, 0)));
  }
  return impl.independent([&] {
    std::string bytes;
    for (const std::string& column : impl.row_columns) {
      bytes += column + '\0' + impl.file.read_row_bytes(column, at, 1);
    }
    if (impl.layout.weights) {
      const auto [offset, length] = impl.weights_of(at);
      bytes += kWeights + '\0';
      if (length > 0) bytes += impl.file.read_row_bytes(kWeights, offset, length);
    }
    return nonzero(fnv1a64(bytes));
  });
}

// A pending row holds no checksum (create, requeue_run and write_run of a
// pending result store 0): one that does had its status (or its checksum)
// damaged, and is damaged itself — else a finished run whose status byte
// turned 0 would read as pending and drop out of every check.
std::string ResultsFile::row_damage(int row) const {
  const Impl& impl = *impl_;
  if (!impl.has_checksums) return "";
  const auto at = static_cast<std::uint64_t>(row);
  try {
    const std::int64_t code = impl.ints(kStatus, at, 1).at(0);
    const std::int64_t stored = impl.ints(kChecksum, at, 1).at(0);
    if (code == static_cast<std::int64_t>(RunStatus::kPending)) {
      if (stored == 0) return "";
      return kStatus + "[" + std::to_string(row) + "] = 0 (pending) but " + kChecksum + "[" +
             std::to_string(row) + "] is set (only a row with a result has one): the status "
             "or the checksum is damaged";
    }
    read_run(row);  // every value in range (rule 1 hashes what it returns)
    if (stored == 0) return "no checksum";
    if (static_cast<std::uint64_t>(stored) != row_checksum(row)) return "checksum mismatch";
  } catch (const std::exception& e) {
    return e.what();  // unreadable is damaged too
  }
  return "";
}

bool ResultsFile::row_damaged(int row) const { return !row_damage(row).empty(); }

std::vector<int> ResultsFile::damaged_rows() const {
  std::vector<int> damaged;
  if (!impl_->has_checksums) return damaged;
  const std::vector<std::int64_t> codes = impl_->ints(kStatus);
  const std::vector<std::int64_t> checksums = impl_->ints(kChecksum);
  for (int row = 0; row < impl_->num_runs; ++row) {
    const auto at = static_cast<std::size_t>(row);
    if (codes[at] == static_cast<std::int64_t>(RunStatus::kPending) && checksums[at] == 0) {
      continue;
    }
    if (row_damaged(row)) damaged.push_back(row);
  }
  return damaged;
}

std::vector<std::string> ResultsFile::structure_problems() const {
  std::vector<std::string> problems;
  try {
    const std::vector<std::string> ids = read_run_ids();
    std::set<std::string> seen;
    for (std::size_t row = 0; row < ids.size(); ++row) {
      if (ids[row].empty()) {
        problems.push_back("row " + std::to_string(row) + " has no run id");
      } else if (!seen.insert(ids[row]).second) {
        problems.push_back("run id " + ids[row] + " repeats (row " + std::to_string(row) + ")");
      }
      if (problems.size() >= 5) break;
    }
    read_statuses();
    read_canonical();
  } catch (const std::exception& e) {
    problems.push_back(e.what());
  }
  return problems;
}

bool ResultsFile::has_checksums() const { return impl_->has_checksums; }
std::int64_t ResultsFile::checksum_version() const { return impl_->checksum_version; }

void ResultsFile::requeue_run(int row) {
  Impl& impl = *impl_;
  const std::int64_t zero = 0;
  impl.independent([&] {
    impl.file.write_rows(kStatus, static_cast<std::uint64_t>(row), 1, &zero);
    if (impl.has_checksums) impl.file.write_rows(kChecksum, static_cast<std::uint64_t>(row), 1, &zero);
  });
}

}  // namespace phnn
