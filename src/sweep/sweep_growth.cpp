// src/sweep/sweep_growth.cpp — run-set comparison and the new version of a
// results file whose sweep grew (see include/phnn/sweep/sweep_growth.h).
#include "phnn/sweep/sweep_growth.h"

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "phnn/store/scratch_file.h"
#include "results_copy.h"

namespace phnn {
namespace {

using KeyValues = std::map<std::string, std::string>;

// "system=duffing;model=node;..." -> {system: duffing, model: node, ...}.
KeyValues split_canonical(const std::string& canonical) {
  KeyValues fields;
  std::size_t start = 0;
  while (start <= canonical.size()) {
    std::size_t end = canonical.find(';', start);
    if (end == std::string::npos) end = canonical.size();
    const std::string item = canonical.substr(start, end - start);
    const std::size_t eq = item.find('=');
    if (eq != std::string::npos) fields[item.substr(0, eq)] = item.substr(eq + 1);
    start = end + 1;
  }
  return fields;
}

// The grid point of a run: the axes of a sweep file's [grid] tables.
const char* const kGridAxes[] = {"system", "model", "integrator", "size", "n_train",
                                 "regularizer", "seed"};

std::string grid_point(const KeyValues& fields) {
  std::string point;
  for (const char* axis : kGridAxes) {
    auto it = fields.find(axis);
    point += std::string(axis) + "=" + (it == fields.end() ? "" : it->second) + ";";
  }
  return point;
}

// "duffing phnn-jr-rk2 small n_train=25 none seed=0".
std::string describe_point(const KeyValues& f) {
  auto get = [&](const char* key) {
    auto it = f.find(key);
    return it == f.end() ? std::string("?") : it->second;
  };
  return get("system") + " " + get("model") + "-" + get("integrator") + " " + get("size") +
         " n_train=" + get("n_train") + " " + get("regularizer") + " seed=" + get("seed");
}

// "steps: 50000 -> 25000; lr: 0.001 -> 0.0001" (keys in the order of `after`
// then keys only `before` has).
std::string describe_difference(const KeyValues& before, const KeyValues& after) {
  std::string text;
  auto add = [&](const std::string& key, const std::string& a, const std::string& b) {
    text += (text.empty() ? "" : "; ") + key + ": " + a + " -> " + b;
  };
  for (const auto& [key, value] : after) {
    auto it = before.find(key);
    if (it == before.end()) {
      add(key, "(unset)", value);
    } else if (it->second != value) {
      add(key, it->second, value);
    }
  }
  for (const auto& [key, value] : before) {
    if (!after.count(key)) add(key, value, "(unset)");
  }
  return text;
}

struct ChangeGroup {
  int count = 0;
  std::string example;
};

}  // namespace

bool RunSetComparison::same_runs_in_order() const {
  if (added || !dropped_pending_rows.empty() || refused()) return false;
  for (std::size_t i = 0; i < file_row_of_run.size(); ++i) {
    if (file_row_of_run[i] != static_cast<int>(i)) return false;
  }
  return true;
}

RunSetComparison compare_run_sets(const std::vector<std::string>& file_canonical,
                                  const std::vector<RunStatus>& file_status,
                                  const std::vector<RunConfig>& sweep_runs) {
  if (file_canonical.size() != file_status.size()) {
    throw std::invalid_argument("compare_run_sets: " + std::to_string(file_canonical.size()) +
                                " canonical configurations but " +
                                std::to_string(file_status.size()) + " statuses");
  }
  std::map<std::string, int> file_row;
  for (std::size_t row = 0; row < file_canonical.size(); ++row) {
    file_row.emplace(file_canonical[row], static_cast<int>(row));
  }
  RunSetComparison result;
  std::set<int> kept_rows;
  std::map<std::string, KeyValues> added_at_point;  // grid point -> fields of the new run
  for (const RunConfig& run : sweep_runs) {
    const std::string canonical = run.canonical();
    auto it = file_row.find(canonical);
    result.file_row_of_run.push_back(it == file_row.end() ? -1 : it->second);
    if (it != file_row.end()) {
      kept_rows.insert(it->second);
      continue;
    }
    ++result.added;
    KeyValues fields = split_canonical(canonical);
    added_at_point.emplace(grid_point(fields), std::move(fields));
  }
  std::map<std::string, ChangeGroup> groups;  // difference -> count, example
  for (std::size_t row = 0; row < file_canonical.size(); ++row) {
    if (kept_rows.count(static_cast<int>(row))) continue;
    const KeyValues before = split_canonical(file_canonical[row]);
    auto replacement = added_at_point.find(grid_point(before));
    if (replacement != added_at_point.end()) {
      ChangeGroup& group = groups[describe_difference(before, replacement->second)];
      if (group.count++ == 0) group.example = describe_point(before);
    } else if (file_status[row] == RunStatus::kPending) {
      result.dropped_pending_rows.push_back(static_cast<int>(row));
    } else {
      result.removed_result_rows.push_back(static_cast<int>(row));
    }
  }
  for (const auto& [difference, group] : groups) {
    result.changes.push_back(difference + " (" + std::to_string(group.count) +
                             (group.count == 1 ? " run: " : " runs, e.g. ") + group.example + ")");
  }
  return result;
}

namespace {

constexpr std::size_t kListedRows = 5;

std::string refusal_message(const std::string& out, const RunSetComparison& cmp,
                            const std::vector<std::string>& file_canonical) {
  std::string text = out + ": this sweep file does not only add runs to the results file:";
  if (!cmp.changes.empty()) {
    text += "\n  it changes the configuration of runs (a results file holds one configuration "
            "per grid point):";
    for (const std::string& change : cmp.changes) {
      text += "\n    " + change;
      if (change.rfind("system_file:", 0) == 0) {
        text += "\n      (the text of a system file the sweep names, or the contents of a "
                "data-set file of `data`, changed: any byte of them is part of the runs' identity)";
      }
    }
  }
  if (!cmp.removed_result_rows.empty()) {
    text += "\n  " + std::to_string(cmp.removed_result_rows.size()) +
            " runs with results are no longer in it, e.g.:";
    for (std::size_t k = 0; k < std::min(kListedRows, cmp.removed_result_rows.size()); ++k) {
      text += "\n    " + describe_point(split_canonical(file_canonical[cmp.removed_result_rows[k]]));
    }
  }
  return text + "\n  restore the sweep file's settings and runs (and its system files), or "
                "write to a new results file with --out (or another `output`); the file is "
                "unchanged";
}

// The canonical configuration of each row of the old version, checked
// against the runs of the file's own sweep text (when that text hashes to
// the file's sweep_hash): a row whose /runs/canonical differs is damaged
// (its checksum fails too; named in *notes) and is compared by its run from
// the text, so the damage is neither taken for a changed or dropped run nor
// copied. With the text unusable too and the file digest finding the column
// damaged, nothing tells the rows' runs: refused (the file is untouched).
// *text_hash: what the stored sweep text hashes to ("" if it does not parse).
std::vector<std::string> checked_canonical(const ResultsFile& old, std::string* notes,
                                           std::string* text_hash) {
  std::vector<std::string> canonical = old.read_canonical();
  std::optional<Grid> own;
  try {
    const SweepSpec spec = parse_sweep_text(old.sweep_text(), old.path() + "@sweep_text",
                                            old.stored_system_files());
    *text_hash = spec.text_hash;
    if (spec.text_hash == old.sweep_hash()) own = expand_grid(spec);
  } catch (const std::exception&) {
    // unusable: the digest below decides
  }
  if (!own || own->runs.size() != canonical.size()) {
    for (const ResultsFile::Damage& d : old.file_damage()) {
      if (d.object != "/runs/canonical") continue;
      throw RunSetRefused(
          old.path() + ": /runs/canonical is damaged (" + d.what + ") and so is the stored "
          "sweep text (@sweep_text or @sweep_hash; `phnn verify` names them), so the runs of "
          "its rows are unknown; the file is unchanged: move the file aside and run this sweep "
          "again (it rebuilds the file from the journals in " + journal_directory(old.path()) +
          "; runs they lack are trained again)");
    }
    return canonical;
  }
  for (std::size_t row = 0; row < canonical.size(); ++row) {
    const std::string& expected = own->runs[row].canonical();
    if (canonical[row] == expected) continue;
    *notes += "; /runs/canonical[" + std::to_string(row) + "] is damaged (it differs from run " +
              own->runs[row].id() + " of the file's own sweep text), compared as that run";
    canonical[row] = expected;
  }
  return canonical;
}

// What became of the rows of the old version that hold a result, as
// (sweep run, old row) pairs.
struct CopiedRows {
  std::vector<std::pair<int, int>> kept;      // intact: copied bitwise
  std::vector<std::pair<int, int>> repaired;  // damaged: written from the journal's record
  std::vector<std::pair<int, int>> requeued;  // damaged, not in the journals: left pending
};

// Copies every row of `from` that holds a result into its row of `to`. A
// damaged row (its checksum fails) is written from the journals' record of
// its run instead (every result column and its run times), or, if they
// lack it or it does not fit the row, left pending to be trained again.
CopiedRows copy_results(const ResultsFile& from, const std::string& out,
                        const RunSetComparison& cmp,
                        std::map<std::string, RunResult>* journal, ResultsFile* to) {
  const std::vector<RunStatus> status = from.read_statuses();
  std::vector<std::pair<int, int>> rows;  // (row, run)
  for (std::size_t run = 0; run < cmp.file_row_of_run.size(); ++run) {
    const int row = cmp.file_row_of_run[run];
    // A pending row with a checksum is a finished one whose status is
    // damaged: copied (as damaged: repaired from the journal) like the rest.
    if (row < 0 || (status[row] == RunStatus::kPending && !from.row_damaged(row))) continue;
    rows.emplace_back(row, static_cast<int>(run));
  }
  const std::vector<std::pair<int, int>> damaged = results_copy::copy_rows(from, rows, to);
  CopiedRows result;
  for (const auto& [row, run] : rows) {
    if (std::find(damaged.begin(), damaged.end(), std::make_pair(row, run)) == damaged.end()) {
      result.kept.emplace_back(run, row);
    }
  }
  if (damaged.empty()) return result;
  *journal = replay_journals(out);
  const std::vector<std::string> ids = from.read_run_ids();
  for (const auto& [row, run] : damaged) {
    const auto it = journal->find(ids[static_cast<std::size_t>(row)]);
    // A record that does not fit the row is trained again, as on resume.
    if (it != journal->end() && to->rewrite_problem(run, it->second).empty()) {
      to->write_run(run, it->second);
      result.repaired.emplace_back(run, row);
    } else {
      result.requeued.emplace_back(run, row);
    }
  }
  return result;
}

// Every kept row reads back bit for bit as the old version's, every repaired
// row as the journal's record.
void verify_copies(const ResultsFile& from, const std::string& written, const CopiedRows& copied,
                   const std::map<std::string, RunResult>& journal) {
  const ResultsFile check = ResultsFile::open_read_only(written);
  for (const auto& [run, row] : copied.kept) {
    if (!results_copy::same_result(check.read_run(run), from.read_run(row))) {
      throw std::runtime_error(written + ": row " + std::to_string(run) + " does not read back as "
                               "row " + std::to_string(row) + " of the previous version; the "
                               "previous version is left in place");
    }
  }
  const std::vector<std::string> ids = from.read_run_ids();
  for (const auto& [run, row] : copied.repaired) {
    if (!results_copy::same_result(check.read_run(run),
                                   journal.at(ids[static_cast<std::size_t>(row)]))) {
      throw std::runtime_error(written + ": row " + std::to_string(run) + " does not read back as "
                               "the journal's record of its run; the previous version is left "
                               "in place");
    }
  }
}

// "run a, run b" for the old rows of `pairs`.
std::string run_list(const std::vector<std::pair<int, int>>& pairs,
                     const std::vector<std::string>& ids) {
  std::string text;
  for (const auto& pair : pairs) {
    text += (text.empty() ? "" : ", ") + ids[static_cast<std::size_t>(pair.second)];
  }
  return text;
}

}  // namespace

std::string write_grown_results(const std::string& out, const SweepSpec& spec, const Grid& grid,
                                const std::string& program_version) {
  CopiedRows copied;
  std::string notes;  // damaged canonical cells
  std::string stored_text_hash, stored_hash;
  std::vector<std::string> old_ids;
  std::string scratch;
  RunSetComparison cmp;
  {
    const ResultsFile old = ResultsFile::open_read_only(out);
    const std::vector<std::string> canonical = checked_canonical(old, &notes, &stored_text_hash);
    stored_hash = old.sweep_hash();
    cmp = compare_run_sets(canonical, old.read_statuses(), grid.runs);
    if (cmp.refused()) throw RunSetRefused(refusal_message(out, cmp, canonical));
    const std::vector<std::string> studies = results_copy::joined_studies(grid);
    scratch = scratch_path(out, "new-version");
    ResultsFile fresh = ResultsFile::create(
        scratch, MPI_COMM_NULL, grid.runs, studies, spec.name, spec.text, spec.text_hash,
        program_version, results_copy::wider_layout(old.layout(), ResultsLayout::for_runs(grid.runs)),
        ResultsFile::CreateMode::kInPlace);
    results_copy::copy_sessions(old, &fresh);
    std::map<std::string, RunResult> journal;
    copied = copy_results(old, out, cmp, &journal, &fresh);
    fresh.close();
    verify_copies(old, scratch, copied, journal);
    old_ids = old.read_run_ids();
  }
  commit_scratch(scratch, out);
  std::string kept = std::to_string(copied.kept.size()) + " runs with results kept bitwise";
  if (!copied.repaired.empty()) {
    kept += "; " + std::to_string(copied.repaired.size()) +
            " damaged rows (checksum mismatch) repaired from the journals: " +
            run_list(copied.repaired, old_ids);
  }
  if (!copied.requeued.empty()) {
    kept += "; " + std::to_string(copied.requeued.size()) +
            " damaged rows (checksum mismatch) not in the journals, left pending to train "
            "again: " + run_list(copied.requeued, old_ids);
  }
  const std::size_t dropped = cmp.dropped_pending_rows.size();
  std::string what;
  if (cmp.added) {
    what = "the sweep grew by " + std::to_string(cmp.added) + " runs";
  } else if (dropped) {
    what = "the sweep no longer has " + std::to_string(dropped) + " of its pending runs";
  } else {
    what = cmp.same_runs_in_order() ? "the sweep file's text changed, not its runs"
                                    : "the sweep file lists the same runs in another order";
  }
  if (cmp.added && dropped) what += " and no longer has " + std::to_string(dropped) + " pending runs";
  // The stored text is this sweep file's, only the attribute differs: it is
  // damaged, not another sweep (written again like one, every result kept).
  if (stored_text_hash == spec.text_hash && stored_hash != spec.text_hash) {
    what = "damaged: @sweep_hash = " + stored_hash + ", but the stored sweep text hashes to " +
           spec.text_hash + ", this sweep file's hash; written again from the sweep file";
  }
  return out + ": " + what + "; new version of the file with " + kept + notes;
}

}  // namespace phnn
