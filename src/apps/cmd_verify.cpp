// src/apps/cmd_verify.cpp — `phnn verify RESULTS`: what can be checked of a
// results file without changing it: its structure (ids, statuses), the file
// digest of checksum rule 2 (sweep text, configuration columns, /data),
// the configuration against the sweep text, every finished row against its
// checksum, and what `phnn sweep` will do about each damage (the same calls
// decide there: docs/RESULTS_FORMAT.md, "Checksums").
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/commands.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace apps {
namespace {

std::string joined(const std::vector<std::string>& parts) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : ",") + p;
  return out;
}

// The runs of the stored sweep text, or why there are none.
std::optional<Grid> stored_grid(const ResultsFile& file, std::string* problem) {
  try {
    const SweepSpec spec = parse_sweep_text(file.sweep_text(), file.path() + "@sweep_text",
                                            file.stored_system_files());
    if (spec.text_hash != file.sweep_hash()) {
      *problem = "the stored sweep text hashes to " + spec.text_hash + ", the attribute says " +
                 file.sweep_hash();
      return std::nullopt;
    }
    return expand_grid(spec);
  } catch (const std::exception& e) {
    *problem = e.what();
  }
  return std::nullopt;
}

// The file's attributes against each other: the stored sweep text (and
// system files) hash to sweep_hash, and expand to the stored run ids.
std::string configuration_problem(const ResultsFile& file, const std::optional<Grid>& grid) {
  const std::vector<std::string> ids = file.read_run_ids();
  if (ids.size() != grid->runs.size()) {
    return "the sweep text gives " + std::to_string(grid->runs.size()) + " runs, the file holds " +
           std::to_string(ids.size());
  }
  for (std::size_t row = 0; row < ids.size(); ++row) {
    if (ids[row] != grid->runs[row].id()) {
      return "row " + std::to_string(row) + " holds run " + ids[row] + ", the sweep text gives " +
             grid->runs[row].id();
    }
  }
  return "";
}

// What `phnn sweep` does about a damaged object outside the rows.
std::string fix_of(const std::string& object) {
  if (object.rfind("/data/", 0) == 0) {
    const std::string group = object.substr(0, object.find('/', 6));
    return "`phnn sweep` with the file's sweep file regenerates " + group +
           " (its data are deterministic) if the data it makes match the recorded digest, else "
           "refuses: then move the file aside and run the sweep again (it rebuilds the file from "
           "the journals and the data from the sweep's systems, or their `phnn data` files)";
  }
  if (object == "@sweep_hash") {
    return "`phnn sweep` with the file's sweep file (the one whose text is the stored sweep "
           "text) writes the file again from it, every result kept";
  }
  return "`phnn sweep` with the file's sweep file (the one whose text hashes to the file's "
         "sweep_hash) rewrites it from that file";
}

// Rule 2: the objects the file digest finds damaged, with the rows of a
// damaged configuration column. Returns how many.
std::size_t report_file_damage(const ResultsFile& file, const std::optional<Grid>& grid) {
  const std::vector<ResultsFile::Damage> damage = file.file_damage();
  std::map<std::string, std::string> rows;
  if (grid && !damage.empty()) {
    std::vector<std::string> studies;
    for (const auto& s : grid->run_studies) studies.push_back(joined(s));
    for (const auto& d : file.configuration_differences(grid->runs, studies)) {
      rows[d.object] = d.what;
    }
  }
  for (const ResultsFile::Damage& d : damage) {
    const auto r = rows.find(d.object);
    std::printf("phnn verify: damaged: %s: %s%s; %s\n", d.object.c_str(), d.what.c_str(),
                r == rows.end() ? "" : ("; " + r->second).c_str(), fix_of(d.object).c_str());
  }
  std::printf("phnn verify: digests (sweep text, configuration columns, /data): %s\n",
              damage.empty() ? "ok" : (std::to_string(damage.size()) + " objects damaged").c_str());
  return damage.size();
}

// Every finished row against its checksum; each damaged one named with
// what `phnn sweep` will do (the calls it makes: rewrite_problem).
std::size_t report_damaged_rows(const ResultsFile& file) {
  int finished = 0;
  for (RunStatus s : file.read_statuses()) finished += s != RunStatus::kPending ? 1 : 0;
  const std::vector<int> damaged = file.damaged_rows();
  std::printf("phnn verify: checksums (rule %lld): %d finished rows checked, %zu damaged\n",
              static_cast<long long>(file.checksum_version()), finished, damaged.size());
  if (damaged.empty()) return 0;
  const auto journal = replay_journals(file.path());
  const std::vector<std::string> ids = file.read_run_ids();
  for (int row : damaged) {
    const std::string& id = ids[static_cast<std::size_t>(row)];
    const auto it = journal.find(id);
    const std::string problem = it == journal.end() ? "" : file.rewrite_problem(row, it->second);
    const std::string fix =
        it == journal.end() ? "not in the journals; `phnn sweep` on this file trains it again"
        : problem.empty()   ? "the journal holds it; `phnn sweep` on this file repairs it (every "
                              "column rewritten from the record)"
                            : "the journal's record does not fit the row (" + problem +
                                  "); `phnn sweep` on this file trains it again";
    std::printf("phnn verify: damaged: run %s (row %d): %s; %s\n", id.c_str(), row,
                file.row_damage(row).c_str(), fix.c_str());
  }
  return damaged.size();
}

}  // namespace

int run_verify(int argc, char** argv, int first) {
  cli::Parser parser(
      "verify",
      "Checks a results file without changing it: its structure (run ids, statuses),\n"
      "the digests of its sweep text, configuration columns and data sets, every finished\n"
      "row against the checksum written with it, and, for each damage, what `phnn sweep`\n"
      "on the file will do (rewrite it from the sweep file or the journals, or train the\n"
      "run again). Exit 0 if nothing is damaged, 1 otherwise.\n\n"
      "Example: phnn verify results/paper.h5");
  parser.positional("RESULTS", "results file of `phnn sweep` or `phnn train --out`");
  if (!parser.parse(argc, argv, first)) return 0;
  const std::string path = parser.get("RESULTS");
  const ResultsFile file = ResultsFile::open_read_only(path);
  std::printf("phnn verify: %s: sweep '%s' (hash %s), %d runs\n", path.c_str(),
              file.sweep_name().c_str(), file.sweep_hash().c_str(), file.num_runs());
  const std::vector<std::string> problems = file.structure_problems();
  for (const std::string& p : problems) std::printf("phnn verify: structure: %s\n", p.c_str());
  if (!problems.empty()) {
    std::printf("phnn verify: damaged structure: move the file aside; `phnn sweep` rebuilds it "
                "from the journals in %s\n", journal_directory(path).c_str());
    return 1;
  }
  std::printf("phnn verify: structure: ok (run ids unique, statuses valid)\n");
  std::string problem;
  const std::optional<Grid> grid = stored_grid(file, &problem);
  std::size_t damaged = file.checksum_version() == 2 ? report_file_damage(file, grid) : 0;
  if (grid) problem = configuration_problem(file, grid);
  if (!problem.empty()) {
    std::printf("phnn verify: configuration: %s\n", problem.c_str());
    if (file.checksum_version() < 2) {
      std::printf("phnn verify: damaged attributes or configuration columns: move the file "
                  "aside; `phnn sweep` rebuilds it from the journals in %s\n",
                  journal_directory(path).c_str());
    }
    ++damaged;
  } else {
    std::printf("phnn verify: configuration: ok (the sweep text matches its hash, the run ids "
                "its grid)\n");
  }
  if (!file.has_checksums()) {
    std::printf("phnn verify: checksums: none (the file predates them); nothing more to check\n");
    return damaged ? 1 : 0;
  }
  damaged += report_damaged_rows(file);
  return damaged ? 1 : 0;
}

}  // namespace apps
}  // namespace phnn
