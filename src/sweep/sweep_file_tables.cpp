// src/sweep/sweep_file_tables.cpp — walks the tables of a parsed sweep file
// in file order and maps each key onto the defaults of docs/METHOD.md
// (OscillatorOptions, DatasetOptions, TrainerOptions, the grid axes): unknown
// tables and keys, whole-struct validation at the key a message names, and the
// studies' inheritance from [grid] (split from the values: this file knows keys;
// the settings tables' handlers: sweep_file_settings.cpp).
// Size: one handler per key of the format; the keys and their cross-checks stay together.
#include "sweep/sweep_file_tables.h"

#include <algorithm>
#include <functional>
#include <map>
#include <optional>

#include "phnn/config/study_defaults.h"
#include "phnn/sweep/output_check.h"
#include "sweep/sweep_file_adaptive.h"
#include "sweep/sweep_file_search.h"
#include "sweep/sweep_file_settings.h"
#include "sweep/sweep_file_systems.h"
#include "sweep/sweep_file_values.h"

namespace phnn {
namespace {

// Axes of [grid] or of one [study.NAME]; unset axes are inherited.
struct AxisSet {
  std::string title;
  std::optional<std::vector<std::string>> systems;
  /// `data`: the names of its data-set files' systems (their stems).
  std::optional<std::vector<std::string>> data;
  std::optional<std::vector<std::pair<ModelKind, IntegratorKind>>> models;
  std::optional<std::vector<ModelSize>> sizes;
  std::optional<std::vector<int>> n_train;
  std::vector<int> n_train_lines;  // line of each n_train value
  std::optional<std::vector<Regularizer>> regularizers;
  std::optional<std::vector<double>> lambdas;
  int lambdas_line = 0;
  std::optional<std::vector<int>> seeds;
};

// key -> line of the keys a table set.
using KeyLines = std::map<std::string, int>;

const char kTableList[] =
    "[data], [training], [grid], [physics.harmonic], [physics.duffing], "
    "[physics.self-sustained], [study.NAME], [adaptive], [search]";

class TableWalker {
 public:
  TableWalker(const SweepSource& source, SystemFileReader read_system_file)
      : source_(source), values_(source), systems_(source, std::move(read_system_file)) {}

  SweepSpec resolve(const toml::table& root) {
    for (SystemKind kind : all_systems()) spec_.physics[kind] = OscillatorOptions::defaults(kind);
    for (const Entry& e : entries_in_file_order(root)) top_level_entry(e);
    if (!has_name_) {
      fail(1, "missing required key \"name\"; add `name = \"...\"` at the top of the file");
    }
    if (!has_output_) spec_.output = "results/" + sanitize_file_name(spec_.name) + ".h5";
    validate_options();
    if (studies_.empty()) studies_.emplace_back("grid", AxisSet());
    for (const auto& [name, axes] : studies_) spec_.studies.push_back(study_spec(name, axes));
    systems_.check_names();
    spec_.system_files = systems_.files();
    check_lambdas();
    check_knobs_change_runs();
    if (search_table_) read_search();  // first: it refuses [adaptive] beside it
    if (spec_.adaptive.enabled) apply_adaptive(&spec_, adaptive_header_, values_);
    return spec_;
  }

 private:
  [[noreturn]] void fail(int line, const std::string& message) const {
    source_.fail(line, message);
  }

  void top_level_entry(const Entry& e) {
    if (e.key == "name") {
      spec_.name = values_.nonempty_string(e);
      has_name_ = true;
    } else if (e.key == "output") {
      spec_.output = values_.nonempty_string(e);
      has_output_ = true;
    } else if (e.key == "data") {
      data_header_ = e.line;
      data_lines_ = apply(values_.table(e, "[data]"), "[data]", data_handlers(values_, spec_.data));
    } else if (e.key == "training") {
      training_header_ = e.line;
      training_lines_ = apply(values_.table(e, "[training]"), "[training]",
                              training_handlers(values_, spec_.training));
    } else if (e.key == "grid") {
      apply(values_.table(e, "[grid]"), "[grid]", axis_handlers(grid_, /*allow_title=*/false));
    } else if (e.key == "physics") {
      physics_tables(values_.table(e, "[physics.SYSTEM]"));
    } else if (e.key == "study") {
      study_tables(e, values_.table(e, "[study.NAME]"));
    } else if (e.key == "adaptive") {
      adaptive_header_ = e.line;
      spec_.adaptive = read_adaptive_table(e, values_);
    } else if (e.key == "search") {
      search_header_ = e.line;
      search_table_ = &values_.table(e, "[search]");
    } else if (e.value->is_table() || e.value->is_array_of_tables()) {
      fail(e.line,
           "unknown table [" + e.key + "]" +
               did_you_mean(e.key, {"data", "training", "grid", "physics.harmonic",
                                    "physics.duffing", "physics.self-sustained", "study.NAME",
                                    "adaptive", "search"}) +
               "; expected one of: " + kTableList);
    } else {
      fail(e.line, "unknown key " + quoted(e.key) + " in the top level (before any [table])" +
                       did_you_mean(e.key, {"name", "output"}) + "; expected one of: name, output");
    }
  }

  // [search], once [training] and the studies are final.
  void read_search() {
    const TrainingKeySetter set = [this](TrainerOptions& t, const Entry& e) {
      for (auto& [key, handler] : training_handlers(values_, t)) {
        if (key == e.key) {
          handler(e);
          return true;
        }
      }
      return false;
    };
    apply_search(&spec_, *search_table_, search_header_, training_lines_, values_, set);
  }

  void physics_tables(const toml::table& physics) {
    for (const Entry& e : entries_in_file_order(physics)) {
      const std::optional<SystemKind> kind = find_system(e.key);
      if (!kind && !e.value->is_table()) {
        fail(e.line, "key " + quoted(e.key) +
                         " directly in [physics]; physical parameters go "
                         "in [physics.harmonic], [physics.duffing] or [physics.self-sustained]");
      }
      const std::string label = "[physics." + e.key + "]";
      if (!kind) {
        fail(e.line, "unknown system " + quoted(e.key) + " in table " + label +
                         did_you_mean(e.key, system_names()) +
                         "; expected one of: [physics.harmonic], [physics.duffing], "
                         "[physics.self-sustained]");
      }
      physics_header_[*kind] = e.line;
      physics_lines_[*kind] = apply(values_.table(e, label), label,
                                    physics_handlers(values_, *kind, spec_.physics[*kind]));
    }
  }

  void study_tables(const Entry& study, const toml::table& tables) {
    if (tables.empty()) fail(study.line, "[study] names no study; write [study.NAME] tables");
    for (const Entry& e : entries_in_file_order(tables)) {
      const std::string label = "[study." + e.key + "]";
      const toml::table& table = values_.table(e, label);
      const bool bare = !e.key.empty() && std::all_of(e.key.begin(), e.key.end(), [](char c) {
        return is_word_char(c) || c == '-';
      });
      if (!bare) {
        fail(e.line, "study name " + quoted(e.key) +
                         " must be letters, digits, '_' and '-' "
                         "(results files list studies separated by commas)");
      }
      studies_.emplace_back(e.key, AxisSet());
      apply(table, label, axis_handlers(studies_.back().second, /*allow_title=*/true));
    }
  }

  // Runs the handlers of a table's keys; returns the lines of the keys it set.
  KeyLines apply(const toml::table& table, const std::string& label, const Handlers& handlers) {
    KeyLines lines;
    for (const Entry& e : entries_in_file_order(table)) {
      lines.emplace(e.key, e.line);  // toml++ refuses duplicate keys
      const auto handler = std::find_if(handlers.begin(), handlers.end(),
                                        [&](const auto& h) { return h.first == e.key; });
      if (handler == handlers.end()) {
        std::vector<std::string> allowed;
        for (const auto& h : handlers) allowed.push_back(h.first);
        const std::string what =
            e.value->is_table() && !e.value->as_table()->is_inline()
                ? "table [" + label.substr(1, label.size() - 2) + "." + e.key + "]"
                : "key " + quoted(e.key);
        fail(e.line, "unknown " + what + " in " + label + did_you_mean(e.key, allowed) +
                         "; expected one of: " + join(allowed));
      }
      handler->second(e);
    }
    return lines;
  }

  // Whole-struct constraints (e.g. energy_max >= energy_min), reported at
  // the line of the key the message names.
  void validate_options() {
    validate_at([&] { spec_.data.validate(); }, "[data]", data_lines_, data_header_);
    validate_at([&] { spec_.training.validate(); }, "[training]", training_lines_,
                training_header_);
    for (SystemKind kind : all_systems()) {
      const std::string label = "[physics." + to_string(kind) + "]";
      const int header = physics_header_.count(kind) ? physics_header_[kind] : 1;
      validate_at(
          [&] {
            spec_.physics[kind].validate();
            if (kind == SystemKind::kSelfSustained) {
              (void)self_oscillation_interval(spec_.physics[kind].z_coefficients);
            }
          },
          label, physics_lines_[kind], header);
    }
  }

  // Calls `check` (an Options::validate()); on failure rethrows its message at
  // the line of the key of the table that the message names first.
  void validate_at(const std::function<void()>& check, const std::string& label,
                   const KeyLines& key_lines, int header_line) const {
    try {
      check();
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      int line = header_line;
      std::size_t first = std::string::npos;
      for (const auto& [key, key_line] : key_lines) {
        const std::size_t at = find_word(message, key == "seed" ? "data_seed" : key);
        if (at < first) {
          first = at;
          line = key_line;
        }
      }
      fail(line, "in " + label + ": " + message);
    }
  }

  // One study: its axes, else the grid's, else docs/METHOD.md §6 defaults.
  StudySpec study_spec(const std::string& name, const AxisSet& axes) const {
    StudySpec study;
    study.name = name;
    study.title = axes.title;
    // `data` adds its files' systems; with `data` and no `systems` (here or
    // in [grid]) the files are the only systems.
    const std::optional<std::vector<std::string>>& data = axes.data ? axes.data : grid_.data;
    study.systems = axes.systems    ? *axes.systems
                    : grid_.systems ? *grid_.systems
                    : data          ? std::vector<std::string>()
                                    : system_names();
    if (data) study.systems.insert(study.systems.end(), data->begin(), data->end());
    study.models = axes.models ? *axes.models : grid_.models ? *grid_.models : all_model_pairs();
    study.sizes = axes.sizes    ? *axes.sizes
                  : grid_.sizes ? *grid_.sizes
                                : std::vector<ModelSize>{kDefaultSize};
    study.regularizers = axes.regularizers    ? *axes.regularizers
                         : grid_.regularizers ? *grid_.regularizers
                                              : std::vector<Regularizer>{kDefaultRegularizer};
    study.lambdas = axes.lambdas    ? *axes.lambdas
                    : grid_.lambdas ? *grid_.lambdas
                                    : std::vector<double>();
    if (axes.seeds || grid_.seeds) {
      study.seeds = axes.seeds ? *axes.seeds : *grid_.seeds;
    } else {
      for (int s = 0; s < kDefaultSeedCount; ++s) study.seeds.push_back(s);
    }
    const AxisSet* n_train_from = axes.n_train ? &axes : grid_.n_train ? &grid_ : nullptr;
    study.n_train = n_train_from ? *n_train_from->n_train : std::vector<int>{kDefaultNTrain};
    check_n_train(study, n_train_from ? n_train_from->n_train_lines : std::vector<int>());
    return study;
  }

  // n_train <= num_train_max for generated data, <= the file's training pairs
  // for a data-set file: reported at the value's line (`lines` is empty for
  // the default).
  void check_n_train(const StudySpec& study, const std::vector<int>& lines) const {
    const int max = spec_.data.num_train_max;
    bool generated = false;
    for (const std::string& system : study.systems) {
      const SweepSystemFile* f = systems_.file(system);
      generated = generated || !f || !f->is_data();
    }
    for (std::size_t i = 0; i < study.n_train.size(); ++i) {
      const int n = study.n_train[i];
      if (n >= 1 && (n <= max || !generated)) continue;
      const auto max_line = data_lines_.find("num_train_max");
      const int line = i < lines.size()                ? lines[i]
                       : max_line != data_lines_.end() ? max_line->second
                                                       : 1;
      fail(line, "n_train value " + std::to_string(n) + (lines.empty() ? " (the default)" : "") +
                     " of study " + quoted(study.name) + " is outside [1, num_train_max = " +
                     std::to_string(max) + "]; lower it or raise num_train_max in [data]");
    }
    for (const std::string& system : study.systems) {
      const SweepSystemFile* f = systems_.file(system);
      if (!f || !f->is_data()) continue;
      for (std::size_t i = 0; i < study.n_train.size(); ++i) {
        if (study.n_train[i] <= f->data_train_pairs) continue;
        fail(i < lines.size() ? lines[i] : 1,
             "n_train value " + std::to_string(study.n_train[i]) + " of study " +
                 quoted(study.name) + " is more than the " + std::to_string(f->data_train_pairs) +
                 " training pairs of the data-set file " + quoted(f->entry) +
                 "; lower n_train or import more training trajectories");
      }
    }
  }

  // A `lambdas` that multiplies no run (only "none" runs take it): an error.
  void check_lambdas() const {
    const auto no_run = [](const std::string& where) {
      return "lambdas of " + where + " multiplies no run: every run it would apply to has "
             "regularizer \"none\" (lambdas multiplies cn, sn and sr runs); add one of them to "
             "regularizers, or remove lambdas";
    };
    bool grid_used = false;
    for (std::size_t i = 0; i < studies_.size(); ++i) {
      const StudySpec& s = spec_.studies[i];
      const bool used = std::any_of(s.regularizers.begin(), s.regularizers.end(),
                                    [](Regularizer r) { return r != Regularizer::kNone; });
      const AxisSet& own = studies_[i].second;
      if (own.lambdas && !used) fail(own.lambdas_line, no_run("study " + quoted(s.name)));
      grid_used = grid_used || (!own.lambdas && used);
    }
    if (grid_.lambdas && !grid_used) fail(grid_.lambdas_line, no_run("[grid]"));
  }

  // A knob away from its default that no run of the file uses would be
  // silently ignored (no run id names it): an error at its line.
  void check_knobs_change_runs() const {
    bool algorithm1 = false, jr_dg = false;
    for (const StudySpec& s : spec_.studies) {
      // A system file may use Algorithm 1 ([initial] method = "algorithm1").
      for (const std::string& k : s.systems) algorithm1 = algorithm1 || k != "duffing" || spec_.system_file(k);
      for (const auto& m : s.models) {
        jr_dg = jr_dg || m == std::make_pair(ModelKind::kPhnnJr, IntegratorKind::kDg);
      }
    }
    if (spec_.data.energy_sampling != EnergySampling::kAlgorithm1 && !algorithm1) {
      fail(data_lines_.at("energy_sampling"),
           "energy_sampling = \"direct\" changes no run: it replaces Algorithm 1 (harmonic, "
           "self-sustained) and every study is duffing only (Algorithm 2); remove it");
    }
    if (spec_.training.dg_structure_point != DgStructurePoint::kMidpoint && !jr_dg) {
      fail(training_lines_.at("dg_structure_point"),
           "dg_structure_point = \"start\" changes no run: it moves R_theta of phnn-jr-dg, "
           "which no study has; remove it");
    }
  }

  // data = "a.h5" or ["a.h5", "b.h5"]: data-set files, each a system of
  // its own (named by its stem) whose runs use the file's splits.
  std::vector<std::string> data_axis(const Entry& e) const {
    std::vector<const toml::node*> items;
    if (const toml::array* a = e.value->as_array()) {
      for (const toml::node& n : *a) items.push_back(&n);
    } else {
      items.push_back(e.value);
    }
    if (items.empty()) fail(e.line, "data expects a data-set file or a non-empty list of them");
    std::vector<std::string> names;
    for (const toml::node* n : items) {
      const int line = line_of(*n) > 0 ? line_of(*n) : e.line;
      const auto* s = n->as_string();
      if (!s || !is_data_file_entry(s->get())) {
        fail(line, "data expects data-set files (paths ending in .h5, written by `phnn data` or "
                   "`phnn import`, relative to this file); got " + values_.describe(*n));
      }
      const std::string name = systems_.resolve(s->get(), line);
      if (std::find(names.begin(), names.end(), name) != names.end()) {
        fail(line, "data lists " + quoted(s->get()) + " twice, or two files with the stem " +
                       quoted(name) + "; list each data-set file once, with distinct file names");
      }
      names.push_back(name);
    }
    return names;
  }

  Handlers axis_handlers(AxisSet& axes, bool allow_title) const {
    Handlers h;
    if (allow_title) {
      h.emplace_back("title", [this, &axes](const Entry& e) { axes.title = values_.string(e); });
    }
    h.emplace_back("systems", [this, &axes](const Entry& e) {
      axes.systems = values_.systems(
          e, [this](const std::string& value, int line) { return systems_.resolve(value, line); });
    });
    h.emplace_back("data", [this, &axes](const Entry& e) { axes.data = data_axis(e); });
    h.emplace_back("models", [this, &axes](const Entry& e) { axes.models = values_.models(e); });
    h.emplace_back("sizes", [this, &axes](const Entry& e) { axes.sizes = values_.sizes(e); });
    h.emplace_back("n_train", [this, &axes](const Entry& e) {
      axes.n_train_lines.clear();
      axes.n_train = values_.int_axis(e, 1, &axes.n_train_lines);
    });
    h.emplace_back("regularizers",
                   [this, &axes](const Entry& e) { axes.regularizers = values_.regularizers(e); });
    h.emplace_back("lambdas", [this, &axes](const Entry& e) {
      axes.lambdas = values_.number_axis(e);
      axes.lambdas_line = e.line;
    });
    h.emplace_back("seeds", [this, &axes](const Entry& e) { axes.seeds = values_.seeds(e); });
    return h;
  }

  const SweepSource& source_;
  ValueReader values_;
  // Mutable: the const handlers record the systems they read.
  mutable SweepSystems systems_;
  SweepSpec spec_;
  AxisSet grid_;
  std::vector<std::pair<std::string, AxisSet>> studies_;  // file order
  KeyLines data_lines_, training_lines_;
  std::map<SystemKind, KeyLines> physics_lines_;
  std::map<SystemKind, int> physics_header_;
  int data_header_ = 1, training_header_ = 1, adaptive_header_ = 1, search_header_ = 1;
  const toml::table* search_table_ = nullptr;
  bool has_name_ = false, has_output_ = false;
};

}  // namespace

SweepSpec resolve_sweep_tables(const toml::table& root, const SweepSource& source,
                               const SystemFileReader& read_system_file) {
  return TableWalker(source, read_system_file).resolve(root);
}

}  // namespace phnn
