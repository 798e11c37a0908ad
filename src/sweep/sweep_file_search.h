// src/sweep/sweep_file_search.h — the [search] table of a sweep file
// (sweeps/FORMAT.md): rungs, eta, and [training] keys as search axes.
// Internal to the parser.
#pragma once

#include <functional>
#include <map>
#include <string>

#include "phnn/sweep/sweep_file.h"
#include "sweep/sweep_file_values.h"

namespace phnn {

/// Sets one [training] key of `options` from `e` (its value a single
/// element); false when `key` is not a [training] key.
using TrainingKeySetter = std::function<bool(TrainerOptions& options, const Entry& e)>;

/// Reads [search] (`table`, its header at `line`) over the finished
/// [training] options `base`: rungs, eta, criterion, and every other key a
/// [training] key with an array of values (a search axis), each value set
/// through `set` and the combination validated. Fails at the line of a bad
/// key or value.
SearchSpec read_search_table(const toml::table& table, int line, const TrainerOptions& base,
                             const ValueReader& values, const TrainingKeySetter& set);

/// With the studies built: reads [search] into spec->search (not with
/// [adaptive]; [training] may set neither steps nor checkpoints, whose
/// lines `training_lines` gives; a searched regularizer weight and a
/// study's `lambdas` exclude each other) and sets [training] steps to the
/// last rung.
void apply_search(SweepSpec* spec, const toml::table& table, int line,
                  const std::map<std::string, int>& training_lines, const ValueReader& values,
                  const TrainingKeySetter& set);

}  // namespace phnn
