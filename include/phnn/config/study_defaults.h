// include/phnn/config/study_defaults.h — what a study trains when its sweep
// file (or `phnn train`'s command line) does not say: the one place the
// defaults of the grid's axes are written.
#pragma once

#include "phnn/config/model_config.h"
#include "phnn/config/trainer_options.h"

namespace phnn {

/// Training pairs N_train.
inline constexpr int kDefaultNTrain = 25;
/// Model seeds 0 .. kDefaultSeedCount - 1.
inline constexpr int kDefaultSeedCount = 10;
inline constexpr ModelSize kDefaultSize = ModelSize::kSmall;
inline constexpr Regularizer kDefaultRegularizer = Regularizer::kNone;

}  // namespace phnn
