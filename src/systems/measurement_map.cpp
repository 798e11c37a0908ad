// src/systems/measurement_map.cpp — a system file's [measurement] compiled
// (include/phnn/systems/measurement_map.h): GiNaC parses each expression
// over the parameters, the names it does not know become recorded columns,
// muParser evaluates them over one buffer [recorded columns, parameters].
#include "phnn/systems/measurement_map.h"

#include <algorithm>
#include <set>

#include "phnn/systems/system_file.h"
#include "systems/expression_bounds.h"
#include "systems/expression_code.h"

namespace phnn {

struct MeasurementMap::Compiled {
  std::unique_ptr<double[]> vars;
  std::unique_ptr<internal::CompiledExpressions> code;
};

MeasurementMap::MeasurementMap() = default;
MeasurementMap::MeasurementMap(MeasurementMap&&) noexcept = default;
MeasurementMap& MeasurementMap::operator=(MeasurementMap&&) noexcept = default;
MeasurementMap::~MeasurementMap() = default;

namespace {

// Parses `text` (measurement.`state`) with `reader`; the symbols it adds
// must be recordable columns.
GiNaC::ex parse_entry(const SystemDefinition& def, const std::string& state,
                      const std::string& text, GiNaC::parser* reader) {
  const int line = def.line_of("measurement." + state);
  const std::string key = "measurement." + state + " = \"" + text + "\"";
  internal::ExpressionSymbols bounds;
  bounds.constants.insert(def.parameters.begin(), def.parameters.end());
  if (const std::string bad = internal::expression_bound_problem(text, bounds); !bad.empty()) {
    throw SystemFileError(def.file, line, key + " " + bad);
  }
  GiNaC::ex e;
  try {
    e = (*reader)(text);
  } catch (const std::exception& err) {
    throw SystemFileError(def.file, line, key + " is not an expression (" + std::string(err.what()) +
                                              "); write it with + - * / ^, parentheses and functions");
  }
  if (e.has(GiNaC::I)) throw SystemFileError(def.file, line, key + " is complex; states are real");
  std::set<std::string> computed;
  for (const auto& [s, _] : def.measurement) computed.insert(s);
  for (const auto& [name, _] : reader->get_syms()) {
    const bool input = std::find(def.inputs.begin(), def.inputs.end(), name) != def.inputs.end();
    if (computed.count(name) || input || name == "t" || name == "trajectory") {
      throw SystemFileError(def.file, line,
                            key + " reads \"" + name + "\", which is " +
                                (computed.count(name) ? "a state [measurement] computes"
                                 : input              ? "an input"
                                                      : "a reserved column") +
                                "; a measurement may read recorded columns (any other name) and "
                                "parameters");
    }
  }
  return e;
}

}  // namespace

MeasurementMap MeasurementMap::of_system_text(const std::string& text, const std::string& file) {
  const SystemDefinition def = parse_system_definition(text, file);
  MeasurementMap map;
  map.ignored_ = def.measurement_ignore;
  GiNaC::symtab table;
  std::vector<GiNaC::realsymbol> params;
  for (const auto& [name, _] : def.parameters) params.emplace_back(name), table[name] = params.back();
  GiNaC::parser reader(table);
  reader.strict = false;
  std::vector<GiNaC::ex> exprs;
  for (const auto& [state, expr] : def.measurement) {
    exprs.push_back(parse_entry(def, state, expr, &reader));
    map.text_.push_back(state + " = " + expr);
  }
  for (const std::string& s : def.states) {
    const auto it = std::find_if(def.measurement.begin(), def.measurement.end(),
                                 [&](const auto& m) { return m.first == s; });
    if (it == def.measurement.end()) {
      map.source_.push_back(static_cast<int>(map.recorded_.size()));
      map.recorded_.push_back(s);
    } else {
      map.source_.push_back(-1 - static_cast<int>(it - def.measurement.begin()));
    }
  }
  for (const auto& [name, _] : reader.get_syms()) {  // a std::map: alphabetical
    if (table.count(name) == 0 && std::find(map.recorded_.begin(), map.recorded_.end(), name) == map.recorded_.end()) {
      map.recorded_.push_back(name);
    }
  }
  if (exprs.empty()) return map;
  std::vector<std::string> names = map.recorded_, sources;
  for (const auto& [name, _] : def.parameters) names.push_back(name);
  map.compiled_ = std::make_unique<Compiled>();
  map.compiled_->vars.reset(new double[names.size()]());
  for (std::size_t i = 0; i < def.parameters.size(); ++i) {
    map.compiled_->vars[map.recorded_.size() + i] = def.parameters[i].second;
  }
  for (const GiNaC::ex& e : exprs) sources.push_back(internal::muparser_source(e));
  map.compiled_->code = std::make_unique<internal::CompiledExpressions>(sources, map.compiled_->vars.get(), names);
  return map;
}

bool MeasurementMap::identity() const { return !compiled_; }

std::string MeasurementMap::describe() const {
  std::string out;
  for (const std::string& t : text_) out += (out.empty() ? "" : ", ") + t;
  return out;
}

void MeasurementMap::states(const double* recorded, double* states) const {
  const double* computed = nullptr;
  if (compiled_) {
    std::copy(recorded, recorded + recorded_.size(), compiled_->vars.get());
    computed = compiled_->code->eval();
  }
  for (std::size_t i = 0; i < source_.size(); ++i) {
    states[i] = source_[i] >= 0 ? recorded[source_[i]] : computed[-1 - source_[i]];
  }
}

}  // namespace phnn
