// include/phnn/config/setting_columns.h — a run's settings as named
// columns, one value each: the names of the per-run CSV (phnn reduce
// --per-run) and of the results file's /runs/config/<name> datasets, read
// from the canonical key (RunConfig::canonical()). One list of names for
// both (sweeps/FORMAT.md spellings). LibTorch-free.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace phnn {

/// Splits "a=1;b=x,y;c=" into {{"a", "1"}, {"b", "x,y"}, {"c", ""}} (each
/// part at its first '='). Throws std::invalid_argument naming the part if
/// one has no '=' or an empty key, or a key repeats.
std::vector<std::pair<std::string, std::string>> parse_canonical(const std::string& canonical);

/// The canonical pairs under their sweep-file names (`lr` -> `learning_rate`,
/// `tau` -> `dg_min_dx_norm`, ...), keys holding several numbers split into
/// one column each (`e0` -> `energy_min`, `energy_max`; `splits`, `adam`,
/// `newton`, `eeq`, `z`); an unknown key, or one whose split would repeat a
/// name, keeps its name and value. Values as the canonical key spells them.
std::vector<std::pair<std::string, std::string>> setting_columns(const std::string& canonical);

/// The names of several runs' setting_columns(), in order of first appearance.
std::vector<std::string> setting_keys(
    const std::vector<std::vector<std::pair<std::string, std::string>>>& columns);

}  // namespace phnn
