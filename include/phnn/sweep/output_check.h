// include/phnn/sweep/output_check.h — what is at a sweep's output path
// before it writes there, and what it may do with it: resume, create, move a
// damaged file of ours aside, or refuse (never destroy what is not ours).
#pragma once

#include <string>

namespace phnn {

/// What inspect_output() found at the output path.
enum class OutputState {
  kMissing,     ///< nothing there: create
  kResumable,   ///< a phnn results file of this sweep: resume
  kOtherText,   ///< a phnn results file of another sweep text: compare the runs (sweep_growth.h)
  kEmpty,       ///< an empty regular file (a crash right after creating it): move aside, create
  kDamaged,     ///< HDF5 signature but unreadable (truncated): move aside, rebuild from journals
  kRefused,     ///< anything else: refuse, message says why and what to do
};

struct OutputCheck {
  OutputState state = OutputState::kMissing;
  /// kDamaged: what is wrong; kRefused: the refusal (names the path and the fix).
  std::string message;
};

/// Inspects `out` (serial, no MPI) for a sweep read from `sweep_path` whose
/// hash is `sweep_hash`. Refused: a directory, FIFO, device or other
/// non-regular file; the sweep file itself; a non-HDF5 file with content; an
/// HDF5 file that is not a phnn results file; another format version; a results file with an impossible value (a
/// status outside 0..3: something other than phnn wrote into it); a journal
/// path (`<out>.journal`) that is not a directory. Never throws.
OutputCheck inspect_output(const std::string& out, const std::string& sweep_path,
                           const std::string& sweep_hash);

/// Renames `path` to `<path>.<reason>-<unix time>` (a free name) and returns
/// the new name; throws std::runtime_error naming both if rename fails.
std::string move_aside(const std::string& path, const std::string& reason);

/// Why the file system cannot hold `out` and the names made from it (its
/// lock, journal and scratch files: up to kLongestSuffix more bytes), ""
/// if it can: a name longer than the directory allows (NAME_MAX), or a path
/// longer than PATH_MAX.
std::string output_name_problem(const std::string& out);
constexpr std::size_t kLongestSuffix = 24;  // ".damaged-<10-digit time>-k"

/// A sweep name made safe as one path component (the default output is
/// `results/<name>.h5`): characters outside [A-Za-z0-9._+-] (so '/') and a
/// leading '.' become '_'; "" becomes "unnamed". "../../x" → "_._.._x".
std::string sanitize_file_name(const std::string& name);

}  // namespace phnn
