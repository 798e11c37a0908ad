// include/phnn/config/training_settings.h — the table of training settings:
// each written once, with its sweep-file key (also its per-run CSV column),
// its part of the canonical key, its `phnn train` flag and one line of doc.
// The [training] reader, the canonical key, the per-run columns, `phnn
// train`'s flags and the sweep text it writes, and the table in
// sweeps/FORMAT.md read it. Defaults: TrainerOptions' member initializers.
#pragma once

#include <string>
#include <vector>

#include "phnn/config/model_config.h"
#include "phnn/config/trainer_options.h"

namespace phnn {

/// One setting of TrainerOptions.
struct TrainingSetting {
  enum class Kind { kReal, kInteger, kChoice };
  /// When its canonical part is in a run's key (RunConfig::cell_key()).
  enum class InKey {
    kAlways,
    kAwayFromDefault,  // settings added later: old ids unchanged
    kRegularizer,      // lambda_X: as "lambda", when X is the run's regularizer
    kDiscreteGradient, // DG and DG4 only
    kPhnnJrDg,         // PHNN-JR-DG only, away from its default
  };
  /// Sweep-file key in [training], per-run CSV column: "learning_rate".
  const char* key;
  Kind kind;
  /// Canonical-key part ("lr"); settings sharing one are printed together,
  /// comma-separated in table order ("adam=0.9,0.999,1e-08").
  const char* canonical;
  InKey in_key;
  /// `phnn train --FLAG` ("" = none).
  const char* flag;
  /// One line for --help and sweeps/FORMAT.md.
  const char* doc;
  double TrainerOptions::*real = nullptr;
  int TrainerOptions::*integer = nullptr;
  /// kInteger: smallest value allowed.
  int min_integer = 1;
  /// kChoice: its names, in table order, and the value's index among them.
  std::vector<std::string> (*choices)() = nullptr;
  int (*get_choice)(const TrainerOptions&) = nullptr;
  void (*set_choice)(TrainerOptions*, int index) = nullptr;
  /// kChoice: sets the value named `text`; std::invalid_argument naming the
  /// choices otherwise (the enum's EnumNames message).
  void (*parse_choice)(TrainerOptions*, const std::string& text) = nullptr;

  /// The value in `t` as the sweep file and the canonical key spell it
  /// (reals %.17g, choices by name).
  std::string text(const TrainerOptions& t) const;
  /// Whether `t` holds TrainerOptions' default here.
  bool is_default(const TrainerOptions& t) const;
};

/// Every setting of TrainerOptions but `checkpoints` (a list) and
/// `skip_inference` (a [search] rung's, never a user's), in canonical-key
/// order.
const std::vector<TrainingSetting>& training_settings();

/// The table as sweeps/FORMAT.md shows it (Markdown: key, default, values,
/// `phnn train` flag, what it is); a test keeps FORMAT.md equal to it.
std::string training_settings_markdown();

/// The canonical-key parts of a run's training settings, in order:
/// "steps=50000;lr=0.001;adam=0.9,0.999,1e-08;..." (each part preceded by
/// ';'); `checkpoints` and `skip_inference` are appended by the caller.
std::string training_key(const TrainerOptions& t, ModelKind model, IntegratorKind integrator,
                         Regularizer regularizer);

}  // namespace phnn
