// src/store/results_file_config.cpp — the configuration columns of /runs
// (id, canonical, system, ..., weights_layout, /runs/config/*): computed from
// the run list, written by create(), read, compared with a run list and
// rewritten from it (the repair of damage the file digest finds); and the
// whole-column readers of the reducer (results of every row at once).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <algorithm>
#include <map>

#include "phnn/config/model_config.h"
#include "phnn/config/setting_columns.h"
#include "store/results_file_internal.h"

namespace phnn {
namespace results_io {

ConfigColumns::ConfigColumns(const std::vector<RunConfig>& runs,
                             const std::vector<std::string>& run_studies,
                             const std::string& where)
    : studies(run_studies) {
  std::map<std::string, std::size_t> row_of_id;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunConfig& run = runs[i];
    canonical.push_back(run.canonical());
    ids.push_back(run.id());
    require(canonical[i].size() <= kCanonicalLength,
            where + "run " + std::to_string(i) + " has a canonical config of " +
                std::to_string(canonical[i].size()) + " bytes, more than " +
                std::to_string(kCanonicalLength) + ": " + canonical[i]);
    require(run_studies[i].size() <= kStudiesLength,
            where + "run " + std::to_string(i) + " has studies \"" + run_studies[i] +
                "\", longer than " + std::to_string(kStudiesLength) + " bytes");
    const auto [it, inserted] = row_of_id.emplace(ids[i], i);
    require(inserted, where + "runs " + std::to_string(it->second) + " and " + std::to_string(i) +
                          " are the same run (id " + ids[i] + "); the grid must list each run once");
    systems.push_back(run.system_name());
    models.push_back(to_string(run.model));
    integrators.push_back(to_string(run.integrator));
    sizes.push_back(to_string(run.size));
    regularizers.push_back(to_string(run.regularizer));
    n_train.push_back(run.n_train);
    states.push_back(run.n_x);
    seeds.push_back(run.seed);
    weights_offset.push_back(weights_total);
    weights_total += parameter_count(run.model, run.size, run.n_x, run.n_w, run.n_u);
    weights_layout.push_back(
        weight_layout_text(weight_layout(run.model, run.size, run.n_x, run.n_w, run.n_u)));
    weights_layout_length = std::max(weights_layout_length, weights_layout.back().size());
  }
}

// Independent raw-data writes (rank 0 at creation).
void write_config_columns(h5::File& file, const ConfigColumns& c) {
  const auto R = static_cast<std::uint64_t>(c.ids.size());
  file.write_string_rows(kId, 0, c.ids);
  file.write_string_rows(kCanonical, 0, c.canonical);
  file.write_string_rows(kSystem, 0, c.systems);
  file.write_string_rows(kModel, 0, c.models);
  file.write_string_rows(kIntegrator, 0, c.integrators);
  file.write_string_rows(kSize, 0, c.sizes);
  file.write_string_rows(kRegularizer, 0, c.regularizers);
  file.write_string_rows(kStudies, 0, c.studies);
  file.write_rows(kNTrain, 0, R, c.n_train.data());
  file.write_rows(kSeed, 0, R, c.seeds.data());
  if (file.exists(kStates)) file.write_rows(kStates, 0, R, c.states.data());
  if (file.exists(kWeightsOffset)) file.write_rows(kWeightsOffset, 0, R, c.weights_offset.data());
  if (file.exists(kWeightsLayout)) file.write_string_rows(kWeightsLayout, 0, c.weights_layout);
}

namespace {

// One /runs/config column: float64 where each run that has the setting has
// one number that the canonical key spells as %.17g (NaN where a run lacks
// it), else NUL-padded text (empty where it lacks it).
struct SettingColumn {
  std::string key, path;
  bool numeric = true;
  std::vector<double> numbers;
  std::vector<std::string> text;
};

std::vector<SettingColumn> setting_columns_of(const std::vector<std::string>& canonical) {
  std::vector<std::vector<std::pair<std::string, std::string>>> columns;
  for (const std::string& c : canonical) columns.push_back(setting_columns(c));
  const std::size_t R = canonical.size();
  std::vector<SettingColumn> out;
  for (const std::string& key : setting_keys(columns)) {
    SettingColumn column{key, "", true, std::vector<double>(R, kNaN), std::vector<std::string>(R)};
    for (std::size_t r = 0; r < R; ++r) {
      for (const auto& [name, value] : columns[r]) {
        if (name != key) continue;
        column.text[r] = value;
        column.numbers[r] = std::strtod(value.c_str(), nullptr);
        // A number only if the text is the canonical key's spelling of that
        // double (%.17g): a hash of digits or a seed beyond 2^53 stays text.
        char back[40];
        std::snprintf(back, sizeof back, "%.17g", column.numbers[r]);
        column.numeric = column.numeric && !value.empty() && value == back &&
                         std::isfinite(column.numbers[r]);
      }
    }
    std::string name = key;
    std::replace(name.begin(), name.end(), '/', '_');
    column.path = kSettings + "/" + name;
    out.push_back(std::move(column));
  }
  return out;
}

}  // namespace

// /runs/config/<name>: every run setting its own column, named as in the
// per-run CSV (setting_columns()). The canonical key stays the identity.
void write_setting_columns(h5::File& file, const std::vector<std::string>& canonical,
                           bool create) {
  const auto R = static_cast<std::uint64_t>(canonical.size());
  if (create) file.create_group(kSettings);
  for (const SettingColumn& column : setting_columns_of(canonical)) {
    if (create && column.numeric) {
      file.create_dataset(column.path, h5::Type::kFloat64, {R}, 0, kNaN);
    } else if (create) {
      std::size_t length = 1;
      for (const std::string& t : column.text) length = std::max(length, t.size());
      file.create_dataset(column.path, h5::Type::kString, {R}, length);
    }
    if (column.numeric) {
      file.write_rows(column.path, 0, R, column.numbers.data());
    } else {
      file.write_string_rows(column.path, 0, column.text);
    }
    if (!create) continue;
    file.set_attribute(column.path, "description",
                       "run setting `" + column.key + "` of each run (sweeps/FORMAT.md; per-run "
                       "CSV column of the same name)" +
                           (column.numeric ? "; NaN: the run has no such setting" : std::string()));
  }
}

std::vector<std::string> configuration_columns(const h5::File& file) {
  std::vector<std::string> columns;
  for (const std::string* name : {&kId, &kCanonical, &kSystem, &kModel, &kIntegrator, &kSize,
                                  &kRegularizer, &kNTrain, &kSeed, &kStates, &kStudies,
                                  &kWeightsOffset, &kWeightsLayout}) {
    if (file.exists(*name)) columns.push_back(*name);
  }
  if (file.exists(kSettings)) {
    for (const std::string& name : file.objects_under(kSettings)) {
      if (file.is_dataset(name)) columns.push_back(name);
    }
  }
  return columns;
}

}  // namespace results_io

using namespace results_io;

namespace {

// "rows 3, 7 (of 2 differing)": the first few differing rows of a column.
std::string listed_rows(const std::vector<std::size_t>& rows) {
  constexpr std::size_t kListed = 5;
  std::string text = rows.size() == 1 ? "row " : "rows ";
  for (std::size_t k = 0; k < std::min(rows.size(), kListed); ++k) {
    text += (k ? ", " : "") + std::to_string(rows[k]);
  }
  if (rows.size() > kListed) text += " and " + std::to_string(rows.size() - kListed) + " more";
  return text;
}

template <class T>
std::vector<std::size_t> differing(const std::vector<T>& stored, const std::vector<T>& expected) {
  std::vector<std::size_t> rows;
  for (std::size_t r = 0; r < expected.size(); ++r) {
    if (r >= stored.size() || std::memcmp(&stored[r], &expected[r], sizeof(T)) != 0) {
      rows.push_back(r);
    }
  }
  return rows;
}

std::vector<std::size_t> differing(const std::vector<std::string>& stored,
                                   const std::vector<std::string>& expected) {
  std::vector<std::size_t> rows;
  for (std::size_t r = 0; r < expected.size(); ++r) {
    if (r >= stored.size() || stored[r] != expected[r]) rows.push_back(r);
  }
  return rows;
}

}  // namespace

std::vector<ResultsFile::Damage> ResultsFile::configuration_differences(
    const std::vector<RunConfig>& runs, const std::vector<std::string>& run_studies) const {
  const Impl& impl = *impl_;
  const ConfigColumns c(runs, run_studies, path() + ": ");
  std::vector<Damage> out;
  auto note = [&](const std::string& column, const std::vector<std::size_t>& rows) {
    if (rows.empty()) return;
    out.push_back({column, listed_rows(rows) + (rows.size() == 1 ? " differs" : " differ") +
                               " from the sweep file's runs"});
  };
  const std::pair<const std::string*, const std::vector<std::string>*> texts[] = {
      {&kId, &c.ids},           {&kCanonical, &c.canonical}, {&kSystem, &c.systems},
      {&kModel, &c.models},     {&kIntegrator, &c.integrators}, {&kSize, &c.sizes},
      {&kRegularizer, &c.regularizers}, {&kStudies, &c.studies},
      {&kWeightsLayout, &c.weights_layout}};
  for (const auto& [name, expected] : texts) {
    if (impl.file.exists(*name)) note(*name, differing(impl.strings(*name), *expected));
  }
  const std::pair<const std::string*, const std::vector<std::int64_t>*> numbers[] = {
      {&kNTrain, &c.n_train}, {&kSeed, &c.seeds}, {&kStates, &c.states},
      {&kWeightsOffset, &c.weights_offset}};
  for (const auto& [name, expected] : numbers) {
    if (impl.file.exists(*name)) note(*name, differing(impl.ints(*name), *expected));
  }
  if (!impl.file.exists(kSettings)) return out;
  for (const SettingColumn& column : setting_columns_of(c.canonical)) {
    if (!impl.file.exists(column.path)) {
      out.push_back({column.path, "missing"});
    } else if (column.numeric) {
      note(column.path, differing(impl.doubles(column.path), column.numbers));
    } else {
      note(column.path, differing(impl.strings(column.path), column.text));
    }
  }
  return out;
}

std::vector<std::string> ResultsFile::read_run_ids() const { return impl_->strings(kId); }
std::vector<std::string> ResultsFile::read_canonical() const {
  return impl_->strings(kCanonical);
}
std::vector<std::string> ResultsFile::read_studies() const { return impl_->strings(kStudies); }
std::vector<std::int64_t> ResultsFile::read_seeds() const { return impl_->ints(kSeed); }

void ResultsFile::rewrite_configuration(const std::vector<RunConfig>& runs,
                                        const std::vector<std::string>& run_studies,
                                        const std::string& sweep_name,
                                        const std::string& sweep_text,
                                        const std::string& sweep_hash) {
  Impl& impl = *impl_;
  const std::string where = path() + ": rewrite_configuration: ";
  require(impl.comm == MPI_COMM_NULL, where + "a serial file only (rank 0's scratch copy)");
  require(static_cast<int>(runs.size()) == impl.num_runs && run_studies.size() == runs.size(),
          where + "got " + std::to_string(runs.size()) + " runs for " +
              std::to_string(impl.num_runs) + " rows");
  const ConfigColumns columns(runs, run_studies, where);
  impl.independent([&] {
    impl.file.set_attribute("/", "sweep_name", sweep_name);
    impl.file.set_attribute("/", "sweep_text", sweep_text);
    impl.file.set_attribute("/", "sweep_hash", sweep_hash);
    write_config_columns(impl.file, columns);
    if (impl.file.exists(kSettings)) write_setting_columns(impl.file, columns.canonical, false);
    return 0;
  });
  impl.read_layout();  // /runs/n_x may have changed
}

std::vector<RunResult> ResultsFile::read_result_columns() const {
  const Impl& impl = *impl_;
  const std::vector<RunStatus> statuses = read_statuses();
  const std::vector<std::string> messages = impl.strings(kMessage);
  std::vector<RunResult> rows(statuses.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].status = statuses[i];
    rows[i].message = messages.at(i);
  }
  for (const ResultColumn* c : impl.result_columns) {  // one the file lacks stays NaN
    if (c->type == ResultColumn::Type::kInt) {
      const std::vector<std::int64_t> values = impl.ints(kRuns + c->name);
      for (std::size_t i = 0; i < rows.size(); ++i) c->set_int(rows[i], values.at(i));
    } else {
      const std::vector<double> values = impl.doubles(kRuns + c->name);
      for (std::size_t i = 0; i < rows.size(); ++i) c->set_double(rows[i], values.at(i));
    }
  }
  return rows;
}

std::vector<double> ResultsFile::read_double_column(const std::string& column) const {
  return impl_->doubles(kRuns + column);
}
std::vector<std::int64_t> ResultsFile::read_int_column(const std::string& column) const {
  return impl_->ints(kRuns + column);
}
std::vector<std::string> ResultsFile::read_string_column(const std::string& column) const {
  return impl_->strings(kRuns + column);
}

}  // namespace phnn
