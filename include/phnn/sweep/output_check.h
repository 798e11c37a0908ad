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
/// path (`<out>.journal`) that is a symbolic link or not a directory; `out`
/// itself a symbolic link (resolve it first) or a file with several names
/// (hard links: another name would escape the writer lock). Never throws.
OutputCheck inspect_output(const std::string& out, const std::string& sweep_path,
                           const std::string& sweep_hash);

/// A sweep writes files, not paths: when `out` is a symbolic link,
/// *resolved is the file it names (realpath), so the writer lock, the
/// journals and the atomic replacement are those of that file, and a sweep
/// through the link and one through the file exclude each other. Otherwise
/// *resolved = out. Returns "" or, for a link that names no file, the
/// refusal (naming the path and the fix).
std::string resolve_output_link(const std::string& out, std::string* resolved);

/// Renames `path` to `<path>.<reason>-<unix time>` (a free name) and returns
/// the new name; throws std::runtime_error naming both if rename fails.
std::string move_aside(const std::string& path, const std::string& reason);

/// Why the file system cannot hold `out` and the names made from it (its
/// lock, journal and scratch files: up to kLongestSuffix more bytes), ""
/// if it can: an empty path or one ending in '/', a name longer than the
/// directory allows (NAME_MAX), or a path
/// longer than PATH_MAX.
std::string output_name_problem(const std::string& out);
constexpr std::size_t kLongestSuffix = 24;  // ".damaged-<10-digit time>-k"

/// A sweep name made safe as one path component (the default output is
/// `results/<name>.h5`): characters outside [A-Za-z0-9._+-] (so '/') and a
/// leading '.' become '_'; "" becomes "unnamed". "../../x" → "_._.._x".
std::string sanitize_file_name(const std::string& name);

}  // namespace phnn
