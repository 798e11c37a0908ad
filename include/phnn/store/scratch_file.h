// include/phnn/store/scratch_file.h — how phnn replaces or creates a file
// without ever leaving a half-written one at its name: write a scratch file
// next to it, fsync, rename (atomic on POSIX), fsync the directory.
#pragma once

#include <cstdio>
#include <string>

namespace phnn {

/// The directory of `path`: "." for a bare name, "/" for a file in the root.
std::string parent_directory(const std::string& path);

/// Our scratch name next to `out` (`<out>.<suffix>`), free: a leftover of a
/// crash there (empty, or an HDF5 file) is removed; anything else throws
/// std::runtime_error naming it.
std::string scratch_path(const std::string& out, const std::string& suffix);

/// Copies `from` to `to` (which must not exist); throws std::runtime_error
/// naming both, e.g. for a full disk.
void copy_file(const std::string& from, const std::string& to);

/// fsyncs `scratch`, renames it to `out` (atomic) and fsyncs the directory;
/// throws std::runtime_error naming the step that failed.
void commit_scratch(const std::string& scratch, const std::string& out);

/// Calls write(scratch) on scratch_path(out, suffix), then commits it onto
/// `out`: `out` holds the old file or the whole new one, never half of one.
/// The scratch file is removed if write or the commit throws.
template <class Write>
void write_atomically(const std::string& out, const std::string& suffix, Write&& write) {
  const std::string scratch = scratch_path(out, suffix);
  try {
    write(scratch);
    commit_scratch(scratch, out);
  } catch (...) {
    std::remove(scratch.c_str());
    throw;
  }
}

}  // namespace phnn
