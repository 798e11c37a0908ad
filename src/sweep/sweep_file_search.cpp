// src/sweep/sweep_file_search.cpp — [search]: rungs, eta, criterion, and
// the search axes ([training] keys with a list of values), expanded into one
// TrainerOptions per combination. See sweep_file_search.h.
#include "sweep/sweep_file_search.h"

#include <algorithm>
#include <climits>
#include <stdexcept>

#include "phnn/common/number_text.h"

namespace phnn {

namespace {

// A [training] key the rungs own, or one that would make rungs differ in
// more than their budget.
bool owned_by_rungs(const std::string& key) {
  return key == "steps" || key == "eval_every" || key == "checkpoints";
}

// The value as written in a label: numbers in their shortest round-trip
// spelling, strings as they are.
std::string value_text(const Entry& e, const toml::node& v, const ValueReader& values) {
  if (const auto* s = v.as_string()) return s->get();
  if (v.is_integer() || v.is_floating_point()) return shortest_number(values.number(e, v));
  values.fail(line_of(v), "search axis " + e.key + ": expected numbers or strings as [training] " +
                              e.key + " takes them, got " + values.describe(v));
}

struct Axis {
  std::string key;
  std::vector<Entry> values;  // one Entry per element
  std::vector<std::string> texts;
};

// `key = [v1, v2, ...]` of a [training] key: each element checked by setting it.
Axis read_axis(const Entry& e, const TrainerOptions& base, const ValueReader& values,
               const TrainingKeySetter& set) {
  if (owned_by_rungs(e.key)) {
    values.fail(e.line, "[search] cannot vary " + e.key + ": the rungs set the step budgets (" +
                            "steps) and need one eval_every and no checkpoints; list the budgets in "
                            "rungs = [...]");
  }
  TrainerOptions probe = base;
  const auto set_known = [&](const Entry& one) {
    if (!set(probe, one)) {
      values.fail(e.line, "unknown key " + quoted(e.key) + " in [search]; expected rungs, eta, "
                          "criterion, or a [training] key with a list of values to search");
    }
  };
  const toml::array* items = e.value->as_array();
  if (!items) {
    set_known(e);
    values.fail(e.line, "search axis " + e.key + " expects a list of values, e.g. " + e.key +
                            " = [..., ...], got " + values.describe(*e.value));
  }
  if (items->empty()) values.fail(e.line, "search axis " + e.key + " is empty; list its values");
  Axis axis{e.key, {}, {}};
  for (const toml::node& v : *items) {
    const Entry one{e.key, line_of(v) > 0 ? line_of(v) : e.line, &v};
    set_known(one);
    const std::string text = value_text(one, v, values);
    if (std::find(axis.texts.begin(), axis.texts.end(), text) != axis.texts.end()) {
      values.fail(one.line, "search axis " + e.key + " lists " + text + " twice; list each value once");
    }
    axis.values.push_back(one);
    axis.texts.push_back(text);
  }
  return axis;
}

// rungs = [5000, 15000, 50000]: strictly increasing, each a multiple of
// eval_every.
std::vector<int> read_rungs(const Entry& e, int eval_every, const ValueReader& values) {
  const std::vector<int> rungs = values.int_axis(e, 1, nullptr);
  for (std::size_t i = 0; i < rungs.size(); ++i) {
    if (i > 0 && rungs[i] <= rungs[i - 1]) {
      values.fail(e.line, "rungs must increase: " + std::to_string(rungs[i]) + " follows " +
                              std::to_string(rungs[i - 1]));
    }
    if (rungs[i] % eval_every != 0) {
      values.fail(e.line, "rung " + std::to_string(rungs[i]) + " is not a multiple of eval_every = " +
                              std::to_string(eval_every) + " ([training]); a rung must end on a "
                              "validation step so training on from it equals training straight "
                              "through");
    }
  }
  return rungs;
}

// Every combination of the axes' values, the first axis slowest.
void expand_variants(const std::vector<Axis>& axes, const TrainerOptions& base, int line,
                     const ValueReader& values, const TrainingKeySetter& set, SearchSpec* out) {
  std::vector<std::size_t> at(axes.size(), 0);
  for (;;) {
    TrainerOptions t = base;
    std::string label;
    for (std::size_t a = 0; a < axes.size(); ++a) {
      set(t, axes[a].values[at[a]]);
      label += (label.empty() ? "" : "/") + axes[a].key + "=" + axes[a].texts[at[a]];
    }
    t.steps = out->rungs.back();
    try {
      t.validate();
    } catch (const std::invalid_argument& err) {
      values.fail(line, "[search] combination " + label + ": " + err.what());
    }
    out->variants.push_back(t);
    out->variant_labels.push_back(label);
    std::size_t a = axes.size();
    while (a > 0 && ++at[a - 1] == axes[a - 1].values.size()) at[--a] = 0;
    if (a == 0) return;
  }
}

}  // namespace

SearchSpec read_search_table(const toml::table& table, int line, const TrainerOptions& base,
                             const ValueReader& values, const TrainingKeySetter& set) {
  SearchSpec s;
  s.enabled = true;
  std::vector<Axis> axes;
  int rungs_line = 0;
  for (const Entry& e : entries_in_file_order(table)) {
    if (e.key == "rungs") {
      s.rungs = read_rungs(e, base.eval_every, values);
      rungs_line = e.line;
    } else if (e.key == "eta") {
      s.eta = static_cast<int>(values.integer(e, *e.value, 1, 1000, "an integer in [1, 1000]"));
    } else if (e.key == "criterion") {
      values.choice_index(e, {"validation"});
    } else {
      axes.push_back(read_axis(e, base, values, set));
      s.axes.push_back(e.key);
    }
  }
  if (rungs_line == 0) {
    values.fail(line, "[search] needs rungs = [...], the step budgets of successive halving, "
                      "e.g. rungs = [5000, 15000, 50000]");
  }
  expand_variants(axes, base, line, values, set, &s);
  return s;
}

void apply_search(SweepSpec* spec, const toml::table& table, int line,
                  const std::map<std::string, int>& training_lines, const ValueReader& values,
                  const TrainingKeySetter& set) {
  if (spec->adaptive.enabled) {
    values.fail(line, "[search] and [adaptive] in one sweep file: successive halving decides "
                      "which configurations train on, adaptive seeds how many seeds a cell gets; "
                      "use one of them");
  }
  for (const char* key : {"steps", "checkpoints"}) {
    const auto it = training_lines.find(key);
    if (it != training_lines.end()) {
      values.fail(it->second, std::string("[training] ") + key + " with [search]: the rungs are "
                              "the step budgets; remove " + key + " (the last rung is the full "
                              "budget)");
    }
  }
  spec->search = read_search_table(table, line, spec->training, values, set);
  spec->training.steps = spec->search.rungs.back();
  for (const std::string& axis : spec->search.axes) {
    const bool weight = axis == "lambda_cn" || axis == "lambda_sn" || axis == "lambda_sr";
    for (const StudySpec& study : spec->studies) {
      if (weight && !study.lambdas.empty()) {
        values.fail(line, "[search] varies " + axis + " and study " + quoted(study.name) +
                              " lists lambdas; give the weights in one place");
      }
    }
  }
}

}  // namespace phnn
