// src/report/table_comparisons.cpp — compare_table_cells and
// entries_for_seeds (phnn/report/table_comparisons.h).
#include "phnn/report/table_comparisons.h"

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>

namespace phnn {
namespace {

using CellKey = std::tuple<std::string, std::string, std::string, std::string>;

// One table cell's finished runs by seed (+inf for a diverged run or a
// non-finite MSE) and its first run's index into Grid::runs.
struct CellRuns {
  SeedResults mse;
  int run = -1;
};

std::map<CellKey, CellRuns> cells_of(const std::vector<TableEntry>& entries) {
  std::map<CellKey, CellRuns> out;
  for (const TableEntry& e : entries) {
    if (e.status != RunStatus::kDone && e.status != RunStatus::kDiverged) continue;
    CellRuns& c = out[CellKey{e.study, e.system, e.row, e.column}];
    const bool finite = e.status == RunStatus::kDone && std::isfinite(e.mse);
    c.mse[e.seed] = finite ? e.mse : std::numeric_limits<double>::infinity();
    if (c.run < 0) c.run = e.run;
  }
  return out;
}

std::string name_of(const CellKey& k) {
  return std::get<0>(k) + "/" + std::get<1>(k) + "/" + std::get<2>(k) + "/" + std::get<3>(k);
}

}  // namespace

std::vector<NamedComparison> compare_table_cells(const Grid& grid,
                                                 const std::vector<TableEntry>& entries,
                                                 const ComparisonOptions& options) {
  const std::map<CellKey, CellRuns> cells = cells_of(entries);
  std::vector<NamedComparison> out;
  const auto compare = [&](const CellKey& a, const CellKey& b) {
    const auto ia = cells.find(a), ib = cells.find(b);
    if (ia == cells.end() || ib == cells.end()) return;
    const bool paired = ia->second.run >= 0 && ib->second.run >= 0 &&
                        cells_are_paired(grid.runs[static_cast<std::size_t>(ia->second.run)],
                                         grid.runs[static_cast<std::size_t>(ib->second.run)]);
    out.push_back({name_of(a), name_of(b),
                   compare_cells(ia->second.mse, ib->second.mse, paired, options)});
  };
  for (const StudyTable& t : grid.studies) {
    for (const std::string& system : t.systems) {
      for (const std::string& column : t.columns)
        for (std::size_t i = 0; i < t.rows.size(); ++i)
          for (std::size_t j = i + 1; j < t.rows.size(); ++j)
            compare({t.name, system, t.rows[i], column}, {t.name, system, t.rows[j], column});
      for (const std::string& row : t.rows) {
        for (std::size_t k = 1; k < t.columns.size(); ++k)
          compare({t.name, system, row, t.columns[k]}, {t.name, system, row, t.columns[0]});
        for (std::size_t l = 1; l < t.columns.size(); ++l)
          for (std::size_t k = l + 1; k < t.columns.size(); ++k)
            compare({t.name, system, row, t.columns[k]}, {t.name, system, row, t.columns[l]});
      }
    }
  }
  return out;
}

std::vector<TableEntry> entries_for_seeds(const std::vector<TableEntry>& entries,
                                          const std::vector<int>& seeds) {
  std::map<int, std::vector<const TableEntry*>> by_seed;
  for (const TableEntry& e : entries) by_seed[e.seed].push_back(&e);
  std::vector<TableEntry> out;
  for (std::size_t j = 0; j < seeds.size(); ++j) {
    const auto it = by_seed.find(seeds[j]);
    if (it == by_seed.end()) continue;
    for (const TableEntry* e : it->second) {
      out.push_back(*e);
      out.back().seed = static_cast<int>(j);
    }
  }
  return out;
}

}  // namespace phnn
