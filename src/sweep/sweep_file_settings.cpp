// src/sweep/sweep_file_settings.cpp — see sweep/sweep_file_settings.h.
#include "sweep/sweep_file_settings.h"

#include <algorithm>
#include <array>

#include "phnn/config/data_settings.h"
#include "phnn/config/training_settings.h"

namespace phnn {
namespace {

// A named-choice setting of a table (data or training settings): the
// value's index among `s.choices()` into `options`.
template <typename Setting, typename Options>
Handler choice(const ValueReader& values, const Setting& s, Options& options) {
  return [&values, &s, &options](const Entry& e) {
    s.set_choice(&options, static_cast<int>(values.choice_index(e, s.choices())));
  };
}

}  // namespace

Handlers data_handlers(const ValueReader& values, DatasetOptions& d) {
  Handlers h;
  for (const DataSetting& s : data_settings()) {
    switch (s.kind) {
      case DataSetting::Kind::kReal:
        h.emplace_back(s.key, [&values, &d, &s](const Entry& e) {
          s.set_real(&d, values.number(e, *e.value));
        });
        break;
      case DataSetting::Kind::kInteger:
        h.emplace_back(s.key, [&values, &d, &s](const Entry& e) {
          s.set_integer(&d, values.integer(e, *e.value, s.min_integer, s.max_integer,
                                           "an integer >= " + std::to_string(s.min_integer)));
        });
        break;
      case DataSetting::Kind::kChoice:
        h.emplace_back(s.key, choice(values, s, d));
        break;
    }
  }
  return h;
}

Handlers training_handlers(const ValueReader& values, TrainerOptions& t) {
  Handlers h;
  for (const TrainingSetting& s : training_settings()) {
    switch (s.kind) {
      case TrainingSetting::Kind::kReal:
        h.emplace_back(
            s.key, [&values, &t, &s](const Entry& e) { t.*s.real = values.number(e, *e.value); });
        break;
      case TrainingSetting::Kind::kInteger:
        h.emplace_back(s.key, [&values, &t, &s](const Entry& e) {
          t.*s.integer = values.int_at_least(e, s.min_integer);
        });
        break;
      case TrainingSetting::Kind::kChoice:
        h.emplace_back(s.key, choice(values, s, t));
        break;
    }
  }
  h.emplace_back("checkpoints", [&values, &t](const Entry& e) {
    t.checkpoints = values.int_axis(e, 1, nullptr);
    std::sort(t.checkpoints.begin(), t.checkpoints.end());
  });
  return h;
}

Handlers physics_handlers(const ValueReader& values, SystemKind kind, OscillatorOptions& p) {
  Handlers h;
  for (const PhysicsSetting& s : physics_settings()) {
    if (!s.applies_to(kind)) continue;
    h.emplace_back(s.key, [&values, &p, &s](const Entry& e) {
      if (s.columns.size() == 3) {  // z_coefficients = [z1, z2, z3]
        const std::array<double, 3> v = values.three_numbers(e);
        s.set(&p, {v[0], v[1], v[2]});
      } else {
        s.set(&p, {values.number(e, *e.value)});
      }
    });
  }
  return h;
}

}  // namespace phnn
