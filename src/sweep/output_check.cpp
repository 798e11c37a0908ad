// src/sweep/output_check.cpp — classifies a sweep's output path before the
// sweep touches it (see include/phnn/sweep/output_check.h).
#include "phnn/sweep/output_check.h"

#include <limits.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <stdexcept>

#include "phnn/store/file_probe.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "phnn/store/scratch_file.h"

namespace phnn {
namespace {

// The 8-byte HDF5 format signature at offset 0 (no user block: our files).
bool has_hdf5_signature(const std::string& path) {
  static const char kSignature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  char head[8] = {};
  std::ifstream in(path, std::ios::binary);
  return in.read(head, 8) && std::memcmp(head, kSignature, 8) == 0;
}

OutputCheck refused(const std::string& message) { return {OutputState::kRefused, message}; }

// `out` is an HDF5 file: ours and resumable, damaged, or refused.
OutputCheck inspect_hdf5(const std::string& out, const std::string& sweep_hash) {
  std::string format;
  try {
    format = hdf5_format_attribute(out);
  } catch (const std::exception& e) {
    return {OutputState::kDamaged, std::string("cannot be opened as HDF5 (") + e.what() + ")"};
  }
  if (format != ResultsFile::kFormat) {
    return refused(out + ": an HDF5 file but not a phnn results file (attribute format = \"" +
                   format + "\"); phnn sweep never replaces other files: pass another --out "
                   "path or move it away");
  }
  bool same_text = false;
  try {
    const ResultsFile file = ResultsFile::open_read_only(out);
    same_text = file.sweep_hash() == sweep_hash;
    // Fails its structural checks (a status outside 0..3, a missing or
    // repeated id): moved aside and rebuilt from the journals.
    const std::vector<std::string> problems = file.structure_problems();
    if (!problems.empty()) return {OutputState::kDamaged, problems.front()};
  } catch (const std::exception& e) {
    if (is_hdf5_error(e)) return {OutputState::kDamaged, e.what()};
    return refused(e.what());  // another format version, ...
  }
  if (!same_text) return {OutputState::kOtherText, "written by another sweep text"};
  return {OutputState::kResumable, ""};
}

}  // namespace

OutputCheck inspect_output(const std::string& out, const std::string& sweep_path,
                           const std::string& sweep_hash) {
  try {
    if (const std::string problem = journal_directory_problem(out); !problem.empty()) {
      return refused(problem);
    }
    struct stat st;
    if (::lstat(out.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) {
      return refused(out + ": a symbolic link; pass the file it names with --out");
    }
    if (::stat(out.c_str(), &st) != 0) {
      if (errno == ENOENT) return {OutputState::kMissing, ""};
      return refused(out + ": cannot inspect the output path: " + std::strerror(errno));
    }
    if (!S_ISREG(st.st_mode)) {
      return refused(out + ": not a regular file (" +
                     (S_ISDIR(st.st_mode) ? std::string("a directory") : std::string("a FIFO, "
                                            "device or socket")) +
                     "); pass a results-file path with --out");
    }
    struct stat sweep;
    if (::stat(sweep_path.c_str(), &sweep) == 0 && sweep.st_dev == st.st_dev &&
        sweep.st_ino == st.st_ino) {
      return refused(out + ": is the sweep file itself; pass a results-file path with --out "
                           "(e.g. results/<name>.h5)");
    }
    if (st.st_nlink > 1) {
      return refused(out + ": has " + std::to_string(st.st_nlink) + " names (hard links); a "
                     "sweep replaces its results file by rename, which would leave the other "
                     "names on an old version, and a sweep through another name would not see "
                     "this one's lock: remove the other links (find -samefile) or pass a copy");
    }
    if (st.st_size == 0) return {OutputState::kEmpty, "an empty file"};
    if (!has_hdf5_signature(out)) {
      return refused(out + ": exists and is not an HDF5 file, so not a phnn results file; "
                           "phnn sweep never replaces other files: pass another --out path or "
                           "move it away");
    }
    return inspect_hdf5(out, sweep_hash);
  } catch (const std::exception& e) {
    return refused(out + ": cannot inspect the output path: " + e.what());
  }
}

std::string resolve_output_link(const std::string& out, std::string* resolved) {
  *resolved = out;
  struct stat st;
  if (::lstat(out.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return "";
  char* target = ::realpath(out.c_str(), nullptr);
  if (target == nullptr) {
    return out + ": a symbolic link that names no file (" + std::strerror(errno) +
           "); pass the results file's own path with --out";
  }
  *resolved = target;
  std::free(target);
  return "";
}

std::string move_aside(const std::string& path, const std::string& reason) {
  const std::string base = path + "." + reason + "-" + std::to_string(std::time(nullptr));
  std::string aside = base;
  struct stat st;
  for (int k = 1; ::stat(aside.c_str(), &st) == 0; ++k) aside = base + "-" + std::to_string(k);
  if (std::rename(path.c_str(), aside.c_str()) != 0) {
    throw std::runtime_error(path + ": cannot move it aside to " + aside + ": " +
                             std::strerror(errno));
  }
  return aside;
}

std::string output_name_problem(const std::string& out) {
  if (out.empty() || out.back() == '/') {
    return "the output path \"" + out + "\" names no file; pass a results-file path such as "
           "results/<name>.h5 (--out or `output` in the sweep file)";
  }
  const std::string dir = parent_directory(out);
  const std::string name = out.substr(out.find_last_of('/') + 1);  // npos + 1 == 0
  long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (name_max <= 0) name_max = NAME_MAX;
  if (name.size() + kLongestSuffix > static_cast<std::size_t>(name_max)) {
    return "the output name " + name.substr(0, 40) + "... has " + std::to_string(name.size()) +
           " bytes; with the suffixes of its lock, journal and scratch files (up to " +
           std::to_string(kLongestSuffix) + ") it must fit the file system's " +
           std::to_string(name_max) + ": choose a shorter `output` or --out";
  }
  if (out.size() + kLongestSuffix + 16 > PATH_MAX) {  // + "/rank-NNNNNN.log"
    return "the output path has " + std::to_string(out.size()) + " bytes, too long for PATH_MAX (" +
           std::to_string(PATH_MAX) + ") with its journal files: choose a shorter path";
  }
  return "";
}

std::string sanitize_file_name(const std::string& name) {
  if (name.empty()) return "unnamed";
  std::string out = name;
  for (char& c : out) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '_' || c == '+' || c == '-';
    if (!ok) c = '_';
  }
  if (out[0] == '.') out[0] = '_';
  return out;
}

}  // namespace phnn
