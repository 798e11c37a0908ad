// src/config/training_settings.cpp — the table of training settings
// (phnn/config/training_settings.h) and the canonical-key parts it writes.
// LibTorch-free; touches no file.
#include "phnn/config/training_settings.h"

#include "config/key_parts.h"
#include "phnn/common/number_text.h"
#include "phnn/integrators/integrator.h"

namespace phnn {
namespace {

using Kind = TrainingSetting::Kind;
using InKey = TrainingSetting::InKey;

TrainingSetting real(const char* key, const char* canonical, InKey in_key, const char* flag,
                     const char* doc, double TrainerOptions::*field) {
  TrainingSetting s{key, Kind::kReal, canonical, in_key, flag, doc};
  s.real = field;
  return s;
}

TrainingSetting integer(const char* key, const char* canonical, InKey in_key, const char* flag,
                        const char* doc, int TrainerOptions::*field, int min = 1) {
  TrainingSetting s{key, Kind::kInteger, canonical, in_key, flag, doc};
  s.integer = field;
  s.min_integer = min;
  return s;
}

// A choice among an enum's names: Names gives them, Field the value.
template <typename E, std::size_t N, const EnumNames<E, N>& Names, E TrainerOptions::*Field>
TrainingSetting choice(const char* key, InKey in_key, const char* flag, const char* doc) {
  TrainingSetting s{key, Kind::kChoice, key, in_key, flag, doc};
  s.choices = [] { return Names.names(); };
  s.get_choice = [](const TrainerOptions& t) {
    const std::vector<E> all = Names.all();
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (all[i] == t.*Field) return static_cast<int>(i);
    }
    return -1;
  };
  s.set_choice = [](TrainerOptions* t, int index) {
    t->*Field = Names.all().at(static_cast<std::size_t>(index));
  };
  s.parse_choice = [](TrainerOptions* t, const std::string& text) { t->*Field = Names.parse(text); };
  return s;
}

// Whether a setting's part is in the key of a run of this model,
// integrator and regularizer with options `t`.
bool in_key(const TrainingSetting& s, const TrainerOptions& t, ModelKind model,
            IntegratorKind integrator, Regularizer regularizer) {
  switch (s.in_key) {
    case InKey::kAlways: return true;
    case InKey::kAwayFromDefault: return !s.is_default(t);
    case InKey::kRegularizer:
      return regularizer != Regularizer::kNone &&
             std::string(s.key) == "lambda_" + to_string(regularizer);
    case InKey::kDiscreteGradient: return is_discrete_gradient(integrator);
    case InKey::kPhnnJrDg:
      return model == ModelKind::kPhnnJr && integrator == IntegratorKind::kDg && !s.is_default(t);
  }
  return false;
}

}  // namespace

// In canonical-key order (RunConfig::cell_key()): changing it, a canonical
// spelling or an InKey changes the id of every run.
const std::vector<TrainingSetting>& training_settings() {
  using T = TrainerOptions;
  static const std::vector<TrainingSetting> table = {
      integer("steps", "steps", InKey::kAlways, "steps", "Adam steps", &T::steps),
      real("learning_rate", "lr", InKey::kAlways, "lr", "Adam's learning rate", &T::learning_rate),
      real("adam_beta1", "adam", InKey::kAlways, "", "Adam's beta1", &T::adam_beta1),
      real("adam_beta2", "adam", InKey::kAlways, "", "Adam's beta2", &T::adam_beta2),
      real("adam_eps", "adam", InKey::kAlways, "", "Adam's epsilon", &T::adam_eps),
      integer("batch_size", "batch", InKey::kAlways, "batch",
              "minibatch size (all pairs when N_train <= batch_size)", &T::batch_size),
      integer("eval_every", "eval_every", InKey::kAlways, "eval-every",
              "validation at step 0, every eval_every steps and the last", &T::eval_every),
      real("lambda_cn", "lambda", InKey::kRegularizer, "", "weight of CN", &T::lambda_cn),
      real("lambda_sn", "lambda", InKey::kRegularizer, "", "weight of SN", &T::lambda_sn),
      real("lambda_sr", "lambda", InKey::kRegularizer, "", "weight of SR", &T::lambda_sr),
      choice<LossNorm, 3, kLossNormNames, &T::loss_norm>("loss_norm", InKey::kAwayFromDefault, "",
                                                         "norm of the discrete loss"),
      choice<Precision, 2, kPrecisionNames, &T::precision>(
          "precision", InKey::kAwayFromDefault, "precision",
          "float type of training (float32 trains only; inference stays float64)"),
      choice<InferenceWeights, 2, kInferenceWeightsNames, &T::inference_weights>(
          "inference_weights", InKey::kAwayFromDefault, "", "the weights inference rolls out"),
      real("jacobian_eps", "jac_eps", InKey::kAlways, "",
           "eps of the condition number and stiffness ratio", &T::jacobian_eps),
      real("newton_tolerance", "newton", InKey::kDiscreteGradient, "",
           "DG inference Newton: residual tolerance", &T::newton_tolerance),
      integer("newton_max_iterations", "newton", InKey::kDiscreteGradient, "",
              "DG inference Newton: most updates", &T::newton_max_iterations),
      real("dg_min_dx_norm", "tau", InKey::kDiscreteGradient, "",
           "DG training fallback threshold tau on ‖dx‖", &T::dg_min_dx_norm),
      choice<DgStructurePoint, 2, kDgStructurePointNames, &T::dg_structure_point>(
          "dg_structure_point", InKey::kPhnnJrDg, "", "where PHNN-JR's DG step evaluates R"),
      real("divergence_norm", "divergence", InKey::kAlways, "",
           "a rollout with ‖x‖ above it (or non-finite) diverged", &T::divergence_norm),
  };
  return table;
}

std::string TrainingSetting::text(const TrainerOptions& t) const {
  switch (kind) {
    case Kind::kReal: return exact_number(t.*real);
    case Kind::kInteger: return std::to_string(t.*integer);
    case Kind::kChoice: {
      const int i = get_choice(t);
      return i < 0 ? "unknown" : choices().at(static_cast<std::size_t>(i));
    }
  }
  return "";
}

bool TrainingSetting::is_default(const TrainerOptions& t) const {
  return text(t) == text(TrainerOptions());
}

std::string training_settings_markdown() {
  const TrainerOptions defaults;
  std::string out =
      "| key | default | values | `phnn train` | what |\n|---|---|---|---|---|\n";
  for (const TrainingSetting& s : training_settings()) {
    std::string values = s.kind == Kind::kReal ? "number" : "integer >= " + std::to_string(s.min_integer);
    if (s.kind == Kind::kChoice) {
      values.clear();
      for (const std::string& n : s.choices()) values += (values.empty() ? "" : ", ") + ("`\"" + n + "\"`");
    }
    const std::string value = s.kind == Kind::kChoice ? "`\"" + s.text(defaults) + "\"`"
                              : s.kind == Kind::kReal  ? "`" + shortest_number(defaults.*s.real) + "`"
                                                       : "`" + s.text(defaults) + "`";
    out += "| `" + std::string(s.key) + "` | " + value + " | " + values + " | " +
           (*s.flag ? "`--" + std::string(s.flag) + "`" : "") + " | " + s.doc + " |\n";
  }
  return out;
}

std::string training_key(const TrainerOptions& t, ModelKind model, IntegratorKind integrator,
                         Regularizer regularizer) {
  // Of the three "lambda" settings at most one is in a key.
  return internal::key_parts(
      training_settings(),
      [&](const TrainingSetting& s) { return in_key(s, t, model, integrator, regularizer); },
      [&](const TrainingSetting& s) { return s.text(t); });
}

}  // namespace phnn
