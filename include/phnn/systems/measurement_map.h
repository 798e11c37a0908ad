// include/phnn/systems/measurement_map.h — how the columns of a recording
// become a system's states (a system file's [measurement] table,
// sweeps/FORMAT.md "System files"): states recorded as columns are taken as
// they are; the others are expressions of recorded columns and parameters
// (GiNaC parses them, muParser evaluates them, as H and z). Evaluates
// nothing but its expressions; reads and writes no file.
//
//   [measurement]
//   p = "m*l^2*v"                # the momentum from a recorded velocity v
//   ignore = ["temperature"]     # a column phnn skips
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace phnn {

class MeasurementMap {
 public:
  /// The [measurement] of a system file's text (`file` names it in
  /// errors); the identity when it has none. Throws SystemFileError at the
  /// entry's line: unknown symbols are recorded columns, but not a computed
  /// state, an input or t.
  static MeasurementMap of_system_text(const std::string& text, const std::string& file);
  MeasurementMap(MeasurementMap&&) noexcept;
  MeasurementMap& operator=(MeasurementMap&&) noexcept;
  ~MeasurementMap();

  /// The columns a recording holds besides trajectory, t and the inputs:
  /// the states not computed (in the file's order), then the columns the
  /// expressions read (alphabetical).
  const std::vector<std::string>& recorded() const { return recorded_; }
  /// Columns a recording may hold that are skipped ([measurement] ignore).
  const std::vector<std::string>& ignored() const { return ignored_; }
  /// True when every state is recorded as a column of its name.
  bool identity() const;
  int n_x() const { return static_cast<int>(source_.size()); }
  /// "p = m*l^2*v" per computed state, for summaries.
  std::string describe() const;
  /// The states of one sample from its recorded() values (may be
  /// non-finite: the caller checks, naming the sample).
  void states(const double* recorded, double* states) const;

 private:
  MeasurementMap();
  struct Compiled;
  std::vector<std::string> recorded_, ignored_, text_;
  /// Per state: >= 0 the index of its recorded column, -1 - k the k-th
  /// compiled expression.
  std::vector<int> source_;
  std::unique_ptr<Compiled> compiled_;
};

}  // namespace phnn
