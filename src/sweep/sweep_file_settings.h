// src/sweep/sweep_file_settings.h — the handlers of the settings tables of a
// sweep file ([data], [training], [physics.<system>]): one per key of the
// tables in phnn/config (data_settings.h, training_settings.h), reading the
// entry through a ValueReader into the options. Internal to the parser.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "phnn/config/trainer_options.h"
#include "phnn/data/dataset.h"
#include "phnn/systems/oscillators.h"
#include "sweep/sweep_file_values.h"

namespace phnn {

/// A key's handler: reads the entry and stores the value.
using Handler = std::function<void(const Entry&)>;
using Handlers = std::vector<std::pair<std::string, Handler>>;

/// Every [data] setting into `d`. `values` and `d` must outlive the handlers.
Handlers data_handlers(const ValueReader& values, DatasetOptions& d);
/// Every [training] setting into `t`, then `checkpoints` (a list).
Handlers training_handlers(const ValueReader& values, TrainerOptions& t);
/// Only the parameters `kind` uses (RunConfig::cell_key() hashes exactly
/// these), so a key that would be silently ignored is an error instead.
Handlers physics_handlers(const ValueReader& values, SystemKind kind, OscillatorOptions& p);

}  // namespace phnn
