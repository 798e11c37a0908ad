// src/sweep/sweep_file_adaptive.cpp — [adaptive]: max_seeds, batch, rule and
// the comparisons' cell selectors ("system/models/n_train/size/regularizer"),
// checked against the studies; then every study's seeds grow to max_seeds.
#include "sweep/sweep_file_adaptive.h"

#include <algorithm>
#include <sstream>

#include "phnn/report/tables.h"

namespace phnn {

namespace {

// Largest max_seeds: seeds of one cell are one stack of networks.
constexpr int kMaxAdaptiveSeeds = 10000;

const char kSelectorForm[] =
    "\"system/models/n_train/size/regularizer\", models joined by '+', e.g. "
    "\"duffing/phnn-s-dg+phnn-s-rk2/25/small/none\"";

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, sep)) parts.push_back(part);
  if (!text.empty() && text.back() == sep) parts.emplace_back();
  return parts;
}

// values[i] is spelled names[i].
template <typename T>
T named(const std::string& value, const std::vector<T>& values,
        const std::vector<std::string>& names, const std::string& what,
        const std::string& selector, int line, const ValueReader& reader) {
  const auto it = std::find(names.begin(), names.end(), value);
  if (it == names.end()) {
    reader.fail(line, "comparison cell " + quoted(selector) + ": unknown " + what + " " +
                          quoted(value) + did_you_mean(value, names) + "; expected one of: " +
                          join(names));
  }
  return values[static_cast<std::size_t>(it - names.begin())];
}

CellSelector parse_selector(const std::string& text, int line, const ValueReader& reader) {
  const std::vector<std::string> parts = split(text, '/');
  if (parts.size() != 5) {
    reader.fail(line, "comparison cell " + quoted(text) + " has " + std::to_string(parts.size()) +
                          " '/'-separated fields; write " + kSelectorForm);
  }
  CellSelector s;
  s.text = text;
  s.system = parts[0];
  const std::vector<std::string> model_names = known_model_keys();
  if (parts[1].empty()) {
    reader.fail(line, "comparison cell " + quoted(text) + " names no model; write " +
                          kSelectorForm);
  }
  for (const std::string& m : split(parts[1], '+')) {
    s.models.push_back(named(m, known_model_pairs(), model_names, "model", text, line, reader));
    if (std::count(s.models.begin(), s.models.end(), s.models.back()) > 1) {
      reader.fail(line, "comparison cell " + quoted(text) + " names model " + quoted(m) +
                            " twice; list each model once");
    }
  }
  const std::string& n = parts[2];
  if (n.empty() || n.size() > 9 || !std::all_of(n.begin(), n.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    reader.fail(line, "comparison cell " + quoted(text) + ": n_train " + quoted(n) +
                          " is not a positive integer; write " + kSelectorForm);
  }
  s.n_train = std::stoi(n);
  const std::vector<ModelSize> sizes = {ModelSize::kSmall, ModelSize::kMedium, ModelSize::kLarge};
  s.size = named(parts[3], sizes, {"small", "medium", "large"}, "size", text, line, reader);
  const std::vector<Regularizer> regularizers = {Regularizer::kNone, Regularizer::kCn,
                                                 Regularizer::kSn, Regularizer::kSr};
  s.regularizer = named(parts[4], regularizers, {"none", "cn", "sn", "sr"}, "regularizer", text,
                        line, reader);
  return s;
}

// Whether two selectors can pick the same cell.
bool shares_a_cell(const CellSelector& a, const CellSelector& b) {
  if (a.system != b.system || a.n_train != b.n_train || a.size != b.size ||
      a.regularizer != b.regularizer) {
    return false;
  }
  for (const auto& m : a.models) {
    if (std::find(b.models.begin(), b.models.end(), m) != b.models.end()) return true;
  }
  return false;
}

// comparisons = [["A", "B"], ...]: pairs of cell selectors.
std::vector<SeedComparison> comparisons(const Entry& e, const ValueReader& reader) {
  const toml::array* pairs = e.value->as_array();
  if (!pairs || pairs->empty()) {
    reader.fail(e.line, "comparisons expects a non-empty array of [cell, cell] pairs, each cell " +
                            std::string(kSelectorForm) + "; got " + reader.describe(*e.value));
  }
  std::vector<SeedComparison> out;
  for (const toml::node& pair : *pairs) {
    const int line = line_of(pair) > 0 ? line_of(pair) : e.line;
    const toml::array* two = pair.as_array();
    if (!two || two->size() != 2 || !(*two)[0].is_string() || !(*two)[1].is_string()) {
      reader.fail(line, "each comparison is a pair of two cells, [\"A\", \"B\"], each " +
                            std::string(kSelectorForm) + "; got " + reader.describe(pair));
    }
    SeedComparison c;
    c.line = line;
    c.a = parse_selector(*(*two)[0].value<std::string>(), line, reader);
    c.b = parse_selector(*(*two)[1].value<std::string>(), line, reader);
    if (shares_a_cell(c.a, c.b)) {
      reader.fail(line, "comparison of " + quoted(c.a.text) + " with " + quoted(c.b.text) +
                            ": both sides can pick the same cell, so it could never be "
                            "resolved; compare two different cells");
    }
    out.push_back(std::move(c));
  }
  return out;
}

// Whether some study trains `model` of the selector's system at its
// n_train, size and regularizer.
bool study_has(const SweepSpec& spec, const CellSelector& s,
               const std::pair<ModelKind, IntegratorKind>& model) {
  const auto has = [](const auto& values, const auto& v) {
    return std::find(values.begin(), values.end(), v) != values.end();
  };
  for (const StudySpec& study : spec.studies) {
    if (has(study.systems, s.system) && has(study.models, model) && has(study.n_train, s.n_train) &&
        has(study.sizes, s.size) && has(study.regularizers, s.regularizer)) {
      return true;
    }
  }
  return false;
}

void check_selectors(const SweepSpec& spec, const ValueReader& reader) {
  for (const SeedComparison& c : spec.adaptive.comparisons) {
    for (const CellSelector* s : {&c.a, &c.b}) {
      for (const auto& model : s->models) {
        if (study_has(spec, *s, model)) continue;
        reader.fail(c.line, "comparison cell " + quoted(s->text) + ": no study trains " +
                                model_key(model.first, model.second) + " on " +
                                quoted(s->system) + " at n_train " + std::to_string(s->n_train) +
                                ", size " + to_string(s->size) + ", regularizer " +
                                to_string(s->regularizer) +
                                "; name a cell of the studies' axes");
      }
    }
  }
}

// Keys that only some rules or readings read: refused where they would be
// ignored, at the [adaptive] header.
void check_rule_keys(const AdaptiveSpec& a, bool has_delta, const Entry& e,
                     const ValueReader& values) {
  if (a.rule == AdaptiveRule::kComparisons && a.comparisons.empty()) {
    values.fail(e.line, "rule = \"comparisons\" needs `comparisons = [[\"A\", \"B\"], ...]` in "
                        "[adaptive]: the pairs of cells whose medians a question compares");
  }
  if (a.rule != AdaptiveRule::kComparisons && a.futility) {
    values.fail(e.line, "futility applies to rule = \"comparisons\" only; set that rule or "
                        "remove futility");
  }
  if (a.rule != AdaptiveRule::kComparisons && a.four_way) {
    values.fail(e.line, "reading = \"four-way\" applies to rule = \"comparisons\" only; set that "
                        "rule or remove reading");
  }
  if (has_delta && !a.four_way) {
    values.fail(e.line, "delta is the margin of reading = \"four-way\"; set that reading or "
                        "remove delta");
  }
  if (a.rule != AdaptiveRule::kComparisons && a.grow_one) {
    values.fail(e.line, "grow = \"one\" applies to rule = \"comparisons\" only; set that rule "
                        "or remove grow");
  }
  if (a.rule != AdaptiveRule::kComparisons && !a.comparisons.empty()) {
    values.fail(e.line, "comparisons are read by rule = \"comparisons\" only; set that rule or "
                        "remove them");
  }
}

}  // namespace

AdaptiveSpec read_adaptive_table(const Entry& e, const ValueReader& values) {
  AdaptiveSpec a;
  a.enabled = true;
  bool has_max = false, has_batch = false, has_delta = false;
  const toml::table& table = values.table(e, "[adaptive]");
  for (const Entry& k : entries_in_file_order(table)) {
    if (k.key == "max_seeds") {
      a.max_seeds = static_cast<int>(values.integer(k, *k.value, 1, kMaxAdaptiveSeeds,
                                                    "an integer in [1, 10000]"));
      has_max = true;
    } else if (k.key == "batch") {
      a.batch = static_cast<int>(values.integer(k, *k.value, 1, kMaxAdaptiveSeeds,
                                                "an integer in [1, 10000]"));
      has_batch = true;
    } else if (k.key == "rule") {
      a.rule = values.choice(k, all_adaptive_rules());
    } else if (k.key == "comparisons") {
      a.comparisons = comparisons(k, values);
    } else if (k.key == "futility") {
      if (!k.value->is_boolean()) {
        values.fail(k.line, "futility expects true or false; got " + values.describe(*k.value));
      }
      a.futility = *k.value->value<bool>();
    } else if (k.key == "grow") {
      a.grow_one = values.choice_index(k, {"both", "one"}) == 1;
    } else if (k.key == "reading") {
      a.four_way = values.choice_index(k, {"intervals", "four-way"}) == 1;
    } else if (k.key == "delta") {
      a.delta = values.number(k, *k.value);
      has_delta = true;
      if (!(a.delta > 1.0 && a.delta <= 100.0)) {
        values.fail(k.line, "delta expects a factor in (1, 100] (e.g. 1.5: medians within x1.5 "
                            "are equivalent); got " + values.describe(*k.value));
      }
    } else if (k.key == "stop_confidence") {
      a.stop_confidence = values.number(k, *k.value);
      if (!(a.stop_confidence >= 0.5 && a.stop_confidence <= 0.999)) {
        values.fail(k.line, "stop_confidence expects a number in [0.5, 0.999] (e.g. 0.99: an "
                            "early resolution must hold at 99 %); got " + values.describe(*k.value));
      }
    } else {
      const std::vector<std::string> keys = {"max_seeds", "batch", "rule", "comparisons", "futility",
                                             "grow", "stop_confidence", "reading", "delta"};
      values.fail(k.line, "unknown key " + quoted(k.key) + " in [adaptive]" +
                              did_you_mean(k.key, keys) + "; expected one of: " + join(keys));
    }
  }
  if (!has_max || !has_batch) {
    values.fail(e.line, std::string("[adaptive] needs ") + (has_max ? "" : "max_seeds") +
                            (!has_max && !has_batch ? " and " : "") + (has_batch ? "" : "batch") +
                            ", e.g. max_seeds = 40 and batch = 10 (seeds added to a cell per round)");
  }
  check_rule_keys(a, has_delta, e, values);
  return a;
}

void apply_adaptive(SweepSpec* spec, int line, const ValueReader& values) {
  AdaptiveSpec& a = spec->adaptive;
  a.initial_seeds = spec->studies.front().seeds;
  for (const StudySpec& s : spec->studies) {
    if (s.seeds != a.initial_seeds) {
      values.fail(line, "[adaptive] needs the same `seeds` in every study (round 0 of every "
                        "cell); study " + quoted(s.name) + " differs from study " +
                        quoted(spec->studies.front().name) + ": set `seeds` in [grid] only");
    }
    if (!s.lambdas.empty() && a.rule == AdaptiveRule::kComparisons) {
      values.fail(line, "rule = \"comparisons\" cannot name cells of study " + quoted(s.name) +
                        ", which varies `lambdas`; use rule = \"column-best\"");
    }
  }
  const int initial = static_cast<int>(a.initial_seeds.size());
  if (a.rule == AdaptiveRule::kColumnBest && initial < kMinSeedsForInterval) {
    values.fail(line, "rule = \"column-best\" reads the tables' intervals, which need at least " +
                      std::to_string(kMinSeedsForInterval) + " seeds per cell; give `seeds` at "
                      "least that many (e.g. \"0-9\")");
  }
  if (a.max_seeds < initial) {
    values.fail(line, "[adaptive] max_seeds = " + std::to_string(a.max_seeds) + " is below the " +
                      std::to_string(initial) + " seeds every cell starts with; raise max_seeds "
                      "or give fewer `seeds`");
  }
  check_selectors(*spec, values);
  std::vector<int> seeds = a.initial_seeds;
  int next = *std::max_element(seeds.begin(), seeds.end());
  if (next > 2000000000 - a.max_seeds) {
    values.fail(line, "[adaptive] adds seed numbers above the largest seed, " + std::to_string(next) +
                      ", which leaves no room below 2e9; give smaller `seeds`");
  }
  while (static_cast<int>(seeds.size()) < a.max_seeds) seeds.push_back(++next);
  for (StudySpec& s : spec->studies) s.seeds = seeds;
}

}  // namespace phnn
