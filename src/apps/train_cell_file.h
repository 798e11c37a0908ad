// src/apps/train_cell_file.h — `phnn train --out`: the trained cell written
// as a results file of a one-cell sweep, so that `phnn reduce`, `phnn eval`
// and analysis/ read it like any sweep's. Private to src/apps.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "apps/provenance.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace apps {

/// The cell as a one-study sweep file on `system_entry` (a built-in name,
/// with its physics constants written out from the data's system text, or a
/// system file's path as given).
std::string cell_sweep_text(const CellSpec& cell, const PhSystemData& data,
                            const std::string& system_entry);

/// Writes the cell's results file: the runs of `text` (a one-cell sweep whose
/// system files `read` supplies), the data set (`store_data`), the results.
void write_cell_file(const std::string& path, const CellSpec& cell, const std::string& text,
                     const SystemFileReader& read,
                     const std::function<void(ResultsFile*)>& store_data,
                     const std::vector<RunResult>& results, const Provenance& provenance,
                     const std::string& started);

}  // namespace apps
}  // namespace phnn
