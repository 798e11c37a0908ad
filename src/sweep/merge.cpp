// src/sweep/merge.cpp — shards of one sweep into one results file (see
// include/phnn/sweep/merge.h).
#include "phnn/sweep/merge.h"

#include <sys/stat.h>

#include <cstdlib>
#include <memory>
#include <algorithm>
#include <stdexcept>
#include <utility>

#include "phnn/store/output_path.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/store/scratch_file.h"
#include "results_copy.h"

namespace phnn {

Shard Shard::parse(const std::string& text) {
  const std::size_t slash = text.find('/');
  auto number = [&](const std::string& part, long* value) {
    char* end = nullptr;
    *value = std::strtol(part.c_str(), &end, 10);
    return !part.empty() && *end == '\0';
  };
  long index = -1, count = 0;
  if (slash == std::string::npos || !number(text.substr(0, slash), &index) ||
      !number(text.substr(slash + 1), &count) || count < 1 || count > kMaxShards || index < 0 ||
      index >= count) {
    throw std::invalid_argument("--shard \"" + text + "\": expected I/N with 0 <= I < N <= " +
                                std::to_string(kMaxShards) +
                                ", e.g. --shard 0/8 (in a Slurm array: "
                                "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT)");
  }
  return Shard{static_cast<int>(index), static_cast<int>(count)};
}

std::string Shard::output_path(const std::string& sweep_output) const {
  const std::string suffix = ".shard-" + std::to_string(index) + "-of-" + std::to_string(count);
  const bool h5 = sweep_output.size() >= 3 &&
                  sweep_output.compare(sweep_output.size() - 3, 3, ".h5") == 0;
  return h5 ? sweep_output.substr(0, sweep_output.size() - 3) + suffix + ".h5"
            : sweep_output + suffix + ".h5";
}

namespace {

std::vector<ResultsFile> open_shards(const std::vector<std::string>& shards) {
  if (shards.empty()) throw std::invalid_argument("no shard given: phnn merge OUT SHARD...");
  std::vector<ResultsFile> files;
  for (const std::string& path : shards) {
    try {
      files.push_back(ResultsFile::open_read_only(path));
    } catch (const std::exception& e) {
      // The reason, without the advice meant for `phnn sweep` (after ';').
      const std::string why = e.what();
      throw std::runtime_error(why.substr(0, why.find(';')) +
                               "; phnn merge reads shard results files written by `phnn sweep "
                               "--shard I/N`");
    }
    // Rows are matched by position: a shard whose ids repeat or whose
    // statuses are out of range cannot say which run a row holds.
    if (const auto problems = files.back().structure_problems(); !problems.empty()) {
      throw std::runtime_error("shard " + path + ": damaged: " + problems.front() +
                               "; nothing written: `phnn sweep` on its sweep file with the same "
                               "--shard and --out moves it aside and rebuilds it from its "
                               "journals, or leave the shard out of the merge");
    }
    if (files.back().sweep_hash() != files.front().sweep_hash()) {
      throw std::invalid_argument(path + ": results of sweep '" + files.back().sweep_name() +
                                  "' (hash " + files.back().sweep_hash() + "), but " +
                                  shards.front() + " has hash " + files.front().sweep_hash() +
                                  "; merge only shards of one sweep file");
    }
  }
  return files;
}

// The command that last wrote shard `file` (its latest session's command
// line), to show how to repair it; "" if it recorded none.
std::string last_command(const ResultsFile& file) {
  const std::vector<Provenance> sessions = file.read_sessions();
  for (auto session = sessions.rbegin(); session != sessions.rend(); ++session) {
    for (const auto& [key, value] : *session) {
      if (key == "command_line" && !value.empty()) return value;
    }
  }
  return "";
}

constexpr std::size_t kListedDamage = 5;

// Per row, the shard that gives its result (-1: none); throws if two shards
// hold different results for a row (clocks aside). A damaged row (its
// checksum fails: the check of `phnn verify`) is never a source: the run
// takes a good copy from another shard, named in *notes, or, if no shard has
// one, the merge is refused naming each damaged shard row. *notes also names
// each shard whose results all came from earlier shards (given twice, or a
// copy).
std::vector<int> result_sources(const std::vector<ResultsFile>& files,
                                const std::vector<std::string>& shards, std::string* notes) {
  std::vector<int> source(static_cast<std::size_t>(files.front().num_runs()), -1);
  std::vector<std::pair<std::size_t, int>> damaged;  // (shard, row)
  for (std::size_t s = 0; s < files.size(); ++s) {
    const std::vector<RunStatus> status = files[s].read_statuses();
    const std::vector<int> damaged_here = files[s].damaged_rows();
    int finished = 0, repeated = 0;
    for (std::size_t row = 0; row < source.size(); ++row) {
      // First: a damaged status can make a finished row read as pending.
      if (std::binary_search(damaged_here.begin(), damaged_here.end(), static_cast<int>(row))) {
        damaged.emplace_back(s, static_cast<int>(row));
        continue;
      }
      if (status[row] == RunStatus::kPending) continue;
      ++finished;
      if (source[row] < 0) {
        source[row] = static_cast<int>(s);
        continue;
      }
      ++repeated;
      if (!results_copy::same_result(files[source[row]].read_run(static_cast<int>(row)),
                                     files[s].read_run(static_cast<int>(row)))) {
        throw std::runtime_error("run " + std::to_string(row) + " differs between " +
                                 shards[source[row]] + " and " + shards[s] +
                                 " beyond its wall times (a run's result depends only on its "
                                 "configuration and seed); were they written by different phnn "
                                 "builds or kernels?");
      }
    }
    if (finished > 0 && repeated == finished) {
      *notes += "\nphnn merge: note: " + shards[s] + " adds nothing: its " +
                std::to_string(finished) + " results are all in the shards before it (given "
                "twice, or a copy?)";
    }
  }
  std::string refused;
  std::size_t unrepaired = 0;
  for (const auto& [s, row] : damaged) {
    const std::string where = "shard " + shards[s] + " row " + std::to_string(row) + " (run " +
                              files[s].read_run_ids()[static_cast<std::size_t>(row)] +
                              "): " + files[s].row_damage(row);
    if (source[static_cast<std::size_t>(row)] >= 0) {
      *notes += "\nphnn merge: note: " + where + "; took the good copy in " +
                shards[static_cast<std::size_t>(source[static_cast<std::size_t>(row)])];
      continue;
    }
    if (unrepaired++ < kListedDamage) {
      const std::string command = last_command(files[s]);
      refused += (refused.empty() ? "" : "\n") + where + ", and no other shard holds the run" +
                 (command.empty() ? "" : " (the shard was last written by `" + command + "`)");
    }
  }
  if (unrepaired > 0) {
    if (unrepaired > kListedDamage) {
      refused += "\n... " + std::to_string(unrepaired - kListedDamage) + " more damaged rows";
    }
    throw std::runtime_error(
        refused + "\nnothing written: repair each damaged shard by running `phnn sweep` on its "
                  "sweep file again with the same --shard and --out (it rewrites the row from the "
                  "shard's journal, or trains the run again; `phnn verify SHARD` tells which), or "
                  "leave the shard out of the merge (its runs stay pending)");
  }
  return source;
}

// The objects of `file` that its digests find damaged and whose names start
// with `prefix` ("@sweep_", "/data/duffing"): none in files before rule 2.
bool damaged_under(const ResultsFile& file, const std::string& prefix) {
  for (const ResultsFile::Damage& d : file.file_damage()) {
    if (d.object == prefix || d.object.rfind(prefix + "/", 0) == 0 ||
        (prefix.back() == '_' && d.object.rfind(prefix, 0) == 0)) {
      return true;
    }
  }
  return false;
}

// The shard whose sweep attributes are intact (the first); throws if none.
const ResultsFile& intact_sweep_text(const std::vector<ResultsFile>& files) {
  for (const ResultsFile& file : files) {
    if (!damaged_under(file, "@sweep_")) return file;
  }
  throw std::runtime_error(files.front().path() + " and every other shard: the stored sweep text "
                           "is damaged (its digest differs); nothing written: repair a shard by "
                           "running `phnn sweep` on its sweep file with the same --shard and --out");
}

// Each system's data group from the first shard that holds it intact (its
// digest matches); a damaged group is never copied.
void copy_data_groups(const std::vector<ResultsFile>& files, const SweepSpec& spec,
                      const Grid& grid, ResultsFile* to) {
  std::vector<std::string> systems;
  for (const RunConfig& run : grid.runs) {
    const std::string name = run.system_name();
    if (std::find(systems.begin(), systems.end(), name) == systems.end()) systems.push_back(name);
  }
  for (const std::string& name : systems) {
    const SweepSystemFile* system_file = spec.system_file(name);
    std::string damaged;
    for (const ResultsFile& file : files) {
      if (!file.has_system_data(name)) continue;
      if (damaged_under(file, "/data/" + name)) {
        damaged += (damaged.empty() ? "" : ", ") + file.path();
        continue;
      }
      damaged.clear();
      to->store_system_data(name, file.read_system_data(name), system_file ? system_file->entry : "");
      break;
    }
    if (!damaged.empty()) {
      throw std::runtime_error("/data/" + name + " is damaged in " + damaged + " (its digest "
                               "differs) and no other shard holds it intact; nothing written: "
                               "repair a shard by running `phnn sweep` on its sweep file with the "
                               "same --shard and --out");
    }
  }
}

std::string summary(const std::string& out, std::size_t shards,
                    const std::vector<RunStatus>& status) {
  int counts[4] = {0, 0, 0, 0};
  for (RunStatus s : status) ++counts[static_cast<int>(s)];
  const int finished = counts[1] + counts[2] + counts[3];
  return out + ": " + std::to_string(shards) + " shard" + (shards == 1 ? "" : "s") +
         " merged: " + std::to_string(finished) + " of " + std::to_string(status.size()) +
         " runs with results (" + std::to_string(counts[1]) + " done, " +
         std::to_string(counts[2]) + " diverged, " + std::to_string(counts[3]) + " failed), " +
         std::to_string(counts[0]) + " pending";
}

}  // namespace

std::string merge_shards(const std::vector<std::string>& shards, const std::string& out,
                         const std::string& program_version) {
  const std::string problem = output_problem("merge", out, OutputKind::kResults, shards);
  if (!problem.empty()) throw std::invalid_argument(problem);
  const std::vector<ResultsFile> files = open_shards(shards);
  const ResultsFile& text = intact_sweep_text(files);
  const SweepSpec spec = parse_sweep_text(text.sweep_text(), text.path() + "@sweep_text",
                                          text.stored_system_files());
  const Grid grid = expand_grid(spec);
  ResultsLayout layout = files.front().layout();
  for (const ResultsFile& file : files) layout = results_copy::wider_layout(layout, file.layout());
  std::string notes;
  const std::vector<int> source = result_sources(files, shards, &notes);
  write_atomically(out, "partial", [&](const std::string& scratch) {
    ResultsFile merged = ResultsFile::create(scratch, MPI_COMM_NULL, grid.runs,
                                             results_copy::joined_studies(grid), spec.name,
                                             spec.text, spec.text_hash, program_version, layout,
                                             ResultsFile::CreateMode::kInPlace);
    copy_data_groups(files, spec, grid, &merged);
    for (std::size_t s = 0; s < files.size(); ++s) {
      results_copy::copy_sessions(files[s], &merged);
      std::vector<std::pair<int, int>> rows;
      for (std::size_t row = 0; row < source.size(); ++row) {
        if (source[row] == static_cast<int>(s)) rows.emplace_back(row, row);
      }
      const auto damaged = results_copy::copy_rows(files[s], rows, &merged);
      if (!damaged.empty()) {  // damaged between result_sources and now
        throw std::runtime_error("shard " + shards[s] + " row " +
                                 std::to_string(damaged.front().first) +
                                 ": checksum mismatch (it changed while being merged); nothing "
                                 "written: merge again once no program writes the shards");
      }
    }
    merged.close();
  });
  return summary(out, files.size(), ResultsFile::open_read_only(out).read_statuses()) + notes;
}

}  // namespace phnn
