// src/sweep/sweep_file_tables.h — from a parsed sweep file (a toml++ table)
// to a SweepSpec: docs/METHOD.md defaults overridden by the file. Internal to
// the parser.
#pragma once

#include "phnn/sweep/sweep_file.h"
#include "sweep/sweep_file_source.h"

namespace phnn {

/// Maps the tables and keys of `root` onto SweepSpec (every field but
/// source_path, text and text_hash) and validates them; throws SweepFileError
/// at the line of the first unknown key, wrong value or failed constraint.
/// System files named in `systems` are read by `read_system_file` and
/// compiled (their errors carry the system file's own FILE:LINE).
SweepSpec resolve_sweep_tables(const toml::table& root, const SweepSource& source,
                               const SystemFileReader& read_system_file);

}  // namespace phnn
