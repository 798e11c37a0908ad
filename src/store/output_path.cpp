// src/store/output_path.cpp — see include/phnn/store/output_path.h.
#include "phnn/store/output_path.h"

#include <sys/stat.h>
#include <unistd.h>

#include <fstream>

#include "phnn/store/dataset_file.h"
#include "phnn/store/scratch_file.h"
#include "phnn/store/trajectory_files.h"

namespace phnn {
namespace {

bool same_file(const struct stat& a, const std::string& path) {
  struct stat b;
  return ::stat(path.c_str(), &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

// Whether the existing regular file `out` is a `kind` file phnn wrote.
bool ours(const std::string& out, OutputKind kind) {
  switch (kind) {
    case OutputKind::kResults:
      return false;
    case OutputKind::kDataSet:
      return is_dataset_file(out);
    case OutputKind::kEvalCsv: {
      std::ifstream in(out);
      std::string line;
      return std::getline(in, line) && is_eval_csv_header(line);
    }
    case OutputKind::kTrajectoryCsv:
      return is_phnn_trajectory_csv(out);
  }
  return false;
}

std::string what_we_write(OutputKind kind) {
  switch (kind) {
    case OutputKind::kResults: return "writes a new results file";
    case OutputKind::kDataSet: return "only replaces data-set files it wrote";
    case OutputKind::kEvalCsv:
    case OutputKind::kTrajectoryCsv: return "only replaces CSV files it wrote";
  }
  return "";
}

}  // namespace

bool is_eval_csv_header(const std::string& first_line) {
  return first_line.rfind("h0,t,", 0) == 0 || first_line.rfind("trajectory,t,", 0) == 0;
}

std::string output_problem(const std::string& command, const std::string& out, OutputKind kind,
                           const std::vector<std::string>& inputs) {
  const std::string where = out + ": ";
  if (out.empty()) return where + "an empty path; pass a file name";
  struct stat st;
  if (::stat(out.c_str(), &st) == 0) {
    for (const std::string& input : inputs) {
      if (same_file(st, input)) {
        return where + "is the input " + input + "; pass a new output path";
      }
    }
    if (!S_ISREG(st.st_mode)) {
      return where + "not a regular file (" + (S_ISDIR(st.st_mode) ? "a directory" : "a FIFO, "
             "device or socket") + "); pass a file path";
    }
    if (!ours(out, kind)) {
      return where + "exists; phnn " + command + " " + what_we_write(kind) +
             " and never overwrites other files: pass a new path or move it away";
    }
  }
  const std::string dir = parent_directory(out);
  if (::access(dir.c_str(), W_OK) != 0) {
    return where + "directory " + dir + " does not exist or is not writable; create it or "
           "choose another path";
  }
  return "";
}

}  // namespace phnn
