// src/sweep/resumed_items.cpp — see include/phnn/sweep/resumed_items.h.
// Reads the item state files under `<results>.journal/` and deletes stale
// ones.
#include "phnn/sweep/resumed_items.h"

#include <iostream>
#include <map>
#include <sstream>

#include "phnn/store/cell_checkpoint.h"

namespace phnn {

std::string item_key(const Grid& grid, const std::vector<int>& runs,
                     const std::string& sweep_hash) {
  std::string key = sweep_hash + "\n";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    key += (k ? " " : "") + grid.runs[static_cast<std::size_t>(runs[k])].id();
  }
  return key;
}

namespace {

// The rows of the key's run ids if the key is this sweep's and they are all
// pending runs of one cell; else empty.
std::vector<int> pending_rows_of(const std::string& key, const std::string& sweep_hash,
                                 const std::map<std::string, int>& row_of,
                                 const std::map<int, int>& pending_cell) {
  const std::size_t eol = key.find('\n');
  if (eol == std::string::npos || key.substr(0, eol) != sweep_hash) return {};
  std::istringstream ids(key.substr(eol + 1));
  std::vector<int> rows;
  int cell = -1;
  for (std::string id; ids >> id;) {
    const auto row = row_of.find(id);
    if (row == row_of.end()) return {};
    const auto c = pending_cell.find(row->second);
    if (c == pending_cell.end() || (cell >= 0 && c->second != cell)) return {};
    cell = c->second;
    rows.push_back(row->second);
  }
  return rows;
}

}  // namespace

std::vector<std::vector<int>> resumed_groups(const Grid& grid,
                                             std::vector<std::vector<int>>* pending,
                                             const std::string& out,
                                             const std::string& sweep_hash,
                                             const std::vector<std::vector<int>>& keep) {
  std::map<std::string, int> row_of;
  for (std::size_t r = 0; r < grid.runs.size(); ++r) row_of[grid.runs[r].id()] = static_cast<int>(r);
  std::map<int, int> pending_cell, keep_cell;  // row -> cell, for pending (kept) rows
  for (std::size_t c = 0; c < pending->size(); ++c) {
    for (int row : (*pending)[c]) pending_cell[row] = static_cast<int>(c);
  }
  for (std::size_t c = 0; c < keep.size(); ++c) {
    for (int row : keep[c]) keep_cell[row] = static_cast<int>(c);
  }
  std::vector<std::vector<int>> groups;
  for (const std::string& path : list_cell_checkpoints(out)) {
    remove_cell_checkpoint(path + ".writing");  // a save a kill cut short
    CellCheckpoint saved;
    std::string problem;
    const bool read = read_cell_checkpoint(path, &saved, &problem);
    const std::vector<int> rows =
        read ? pending_rows_of(saved.key, sweep_hash, row_of, pending_cell) : std::vector<int>();
    if (rows.empty() && read && !pending_rows_of(saved.key, sweep_hash, row_of, keep_cell).empty()) {
      continue;  // trained ahead of the round in progress: for a later round
    }
    if (rows.empty()) {  // finished since, another sweep's, or damaged
      if (!problem.empty()) std::cerr << "phnn sweep: " << problem << "; deleted\n";
      remove_cell_checkpoint(path);
      continue;
    }
    for (int row : rows) pending_cell.erase(row);
    groups.push_back(rows);
  }
  for (auto& runs : *pending) {
    std::vector<int> left;
    for (int row : runs) {
      if (pending_cell.count(row)) left.push_back(row);
    }
    runs = left;
  }
  return groups;
}

std::vector<WorkItem> with_resumed(const Grid& grid, const std::vector<std::vector<int>>& groups,
                                   std::vector<WorkItem> planned) {
  std::map<int, int> cell_of;
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    for (int row : grid.cells[c].runs) cell_of[row] = static_cast<int>(c);
  }
  std::vector<WorkItem> items;
  for (const auto& runs : groups) {
    WorkItem item;
    item.cell = cell_of.at(runs.front());
    item.runs = runs;
    item.estimated_cost_s =
        grid.cells[static_cast<std::size_t>(item.cell)].cost_s(static_cast<int>(runs.size()));
    items.push_back(item);
  }
  items.insert(items.end(), planned.begin(), planned.end());
  return items;
}

}  // namespace phnn
