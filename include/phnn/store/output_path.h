// include/phnn/store/output_path.h — the one rule every command's --out
// follows: it never overwrites a file phnn did not write itself, nor an input
// of the same command, and it fails before any work if the path cannot be
// written. (`phnn sweep` resumes its results file instead:
// sweep/output_check.h.)
#pragma once

#include <string>
#include <vector>

namespace phnn {

/// What a command writes to its --out.
enum class OutputKind {
  kResults,  // a results file: never replaced (train, merge write new ones)
  kDataSet,  // a data-set file of `phnn data`: replaced by a new one
  kEvalCsv,  // the CSV of `phnn eval`: replaced by a new one
  kTrajectoryCsv,  // the CSV of `phnn data --csv`: replaced by a new one
};

/// Why `command` must not write `out` ("" if it may): `out` is one of
/// `inputs` (also under another name), is not a regular file, exists and is
/// not a file of `kind` phnn wrote (results files: exists at all), or its
/// directory is missing or not writable. Each reason starts with "<out>: "
/// and says the fix; the caller adds its "phnn <command>: " prefix.
std::string output_problem(const std::string& command, const std::string& out, OutputKind kind,
                           const std::vector<std::string>& inputs);

/// The first line of every CSV `phnn eval` writes starts with one of these.
bool is_eval_csv_header(const std::string& first_line);

}  // namespace phnn
