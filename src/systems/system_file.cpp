// src/systems/system_file.cpp — a system file compiled into a PhSystem:
// GiNaC parses H and z(w) and differentiates them (gradH, the Hessian, z',
// z'', and the Gonzalez defect in closed form when it is a polynomial);
// muParser compiles the results to bytecode for fast evaluation. Reads the
// system file; writes nothing.
// The class (FileSystem) is in file_system.h; its evaluations and the
// checks that evaluate it: system_file_eval.cpp.
#include "phnn/systems/system_file.h"

#include "phnn/systems/oscillators.h"
#include "systems/expression_bounds.h"
#include "systems/expression_code.h"
#include "systems/file_system.h"

#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <ginac/ginac.h>
#include <muParser.h>

namespace phnn {
namespace {

using internal::FileSystem;
using internal::Symbols;

using internal::CompiledExpressions;

std::string to_c(const GiNaC::ex& e) {
  std::ostringstream os;
  os << GiNaC::csrc_double << e;
  return os.str();
}

// The exact rational value of a finite double: v = m 2^(e - 53), m an
// integer of at most 53 bits.
GiNaC::numeric exact(double v) {
  int e = 0;
  const double m = std::ldexp(std::frexp(v, &e), 53);
  return GiNaC::numeric(static_cast<long>(m)) * GiNaC::numeric(2).power(e - 53);
}

const Eigen::IOFormat kRow(Eigen::StreamPrecision, Eigen::DontAlignCols, ", ", ", ");

std::string first_line(const std::string& s) { return s.substr(0, s.find('\n')); }


Symbols make_symbols(const SystemDefinition& def) {
  Symbols s;
  auto add = [&](std::vector<GiNaC::realsymbol>* to, const std::string& name) {
    to->emplace_back(name);
    s.names.push_back(name);
  };
  for (const auto& n : def.states) add(&s.x, n);
  for (const auto& p : def.parameters) add(&s.params, p.first);
  for (const auto& n : def.ports) add(&s.w, n);
  for (std::size_t i = 0; i < def.states.size(); ++i) add(&s.a, "phnn_a" + std::to_string(i));
  for (std::size_t i = 0; i < def.states.size(); ++i) add(&s.d, "phnn_d" + std::to_string(i));
  for (const auto& sym : s.x) s.energy_table[sym.get_name()] = sym;
  for (const auto& sym : s.params) {
    s.energy_table[sym.get_name()] = sym;
    s.dissipation_table[sym.get_name()] = sym;
  }
  for (const auto& sym : s.w) s.dissipation_table[sym.get_name()] = sym;
  return s;
}

std::string names_of(const GiNaC::symtab& table) {
  std::string out;
  for (const auto& [name, _] : table) out += (out.empty() ? "" : ", ") + name;
  return out.empty() ? "(none)" : out;
}

constexpr char kWriteItWith[] =
    "; write it with + - * / ^, parentheses and functions such as sin, cos, exp, log, sqrt";

// Checked against the limits of systems/expression_bounds.h before GiNaC
// parses it (GiNaC folds powers while parsing, without a way to stop).
GiNaC::ex parse_expression(const SystemDefinition& def, const std::string& key,
                           const std::string& text, const GiNaC::symtab& allowed,
                           const std::string& may_use) {
  const int line = def.line_of(key);
  internal::ExpressionSymbols symbols;
  symbols.variables.insert(key == "H" ? def.states.begin() : def.ports.begin(),
                           key == "H" ? def.states.end() : def.ports.end());
  symbols.constants.insert(def.parameters.begin(), def.parameters.end());
  if (const std::string bad = internal::expression_bound_problem(text, symbols); !bad.empty()) {
    throw SystemFileError(def.file, line, key + " = \"" + text + "\" " + bad +
                                              (bad.rfind("is not", 0) == 0 ? kWriteItWith : ""));
  }
  GiNaC::parser reader(allowed);
  reader.strict = false;
  GiNaC::ex e;
  try {
    e = reader(text);
  } catch (const std::exception& err) {
    throw SystemFileError(def.file, line, key + " = \"" + text + "\" is not an expression (" +
                                              first_line(err.what()) + ")" + kWriteItWith);
  }
  for (const auto& [name, _] : reader.get_syms()) {
    if (allowed.count(name) == 0) {
      throw SystemFileError(def.file, line, "unknown symbol \"" + name + "\" in " + key + " = \"" +
                                                text + "\"; " + key + " may use " + may_use + ": " +
                                                names_of(allowed) +
                                                " (declare it under [parameters] if it is a constant)");
    }
  }
  if (e.has(GiNaC::I)) {
    throw SystemFileError(def.file, line, key + " = \"" + text + "\" is complex; energies and "
                                                                 "dissipation laws are real");
  }
  return e;
}

}  // namespace

namespace internal {

FileSystem::FileSystem(SystemDefinition def) : def_(std::move(def)) { compile(); }

std::unique_ptr<CompiledExpressions> FileSystem::make(const std::vector<GiNaC::ex>& exprs,
                                                      const std::string& what) const {
  const std::string key = what.rfind("z", 0) == 0 ? "z" : "H";
  std::vector<std::string> c;
  try {
    for (const auto& e : exprs) c.push_back(internal::muparser_source(e.subs(parameter_values_)));
  } catch (const std::invalid_argument& e) {
    throw SystemFileError(def_.file, def_.line_of(key),
                          "cannot evaluate " + what + " (it contains " + e.what() +
                              "); use the functions sin, cos, tan, exp, log, sqrt, sinh, cosh, "
                              "tanh, asin, acos, atan, abs");
  } catch (const std::exception& e) {  // GiNaC: a pole, e.g. 1/m with m = 0
    std::string zeros;
    for (const auto& [name, value] : def_.parameters) {
      if (value == 0) zeros += (zeros.empty() ? " (" : ", ") + name + " = 0 on line " +
                               std::to_string(def_.line_of("parameters." + name));
    }
    throw SystemFileError(def_.file, def_.line_of(key),
                          "cannot evaluate " + what + " with the values of [parameters]" +
                              (zeros.empty() ? "" : zeros + ")") + ": " + first_line(e.what()) +
                              "; a parameter that divides, or is the argument of log, must not "
                              "be 0: change its value");
  }
  try {
    return std::make_unique<CompiledExpressions>(c, vars_.get(), syms_.names);
  } catch (const mu::Parser::exception_type& e) {
    const bool long_text = e.GetCode() == mu::ecEXPRESSION_TOO_LONG;
    throw SystemFileError(def_.file, def_.line_of(key),
                          "cannot evaluate " + what + " (" + e.GetMsg() +
                              (long_text ? "): written out it exceeds muParser's " +
                                               std::to_string(mu::MaxLenExpression) +
                                               " characters; simplify " + key +
                                               " (fewer nested functions or terms)"
                                         : "); use the functions sin, cos, tan, exp, log, sqrt, "
                                           "sinh, cosh, tanh, asin, acos, atan, abs"));
  }
}

void FileSystem::compile() {
  syms_ = make_symbols(def_);
  const Symbols& s = syms_;
  const std::size_t nx = s.x.size(), np = s.params.size(), nw = s.w.size();
  vars_.reset(new double[s.names.size()]());
  for (std::size_t i = 0; i < np; ++i) {
    vars_[nx + i] = def_.parameters[i].second;
    parameter_values_[s.params[i]] = exact(def_.parameters[i].second);
  }
  w_offset_ = nx + np;
  d_offset_ = w_offset_ + nw + nx;  // after the ports and the midpoint symbols a
  if (!def_.has_energy()) return;  // structure only: nothing to evaluate
  const GiNaC::ex H = parse_expression(def_, "H", def_.energy, s.energy_table,
                                       "the states and parameters");
  std::vector<GiNaC::ex> grad, hess;
  for (std::size_t i = 0; i < nx; ++i) grad.push_back(H.diff(s.x[i]));
  for (std::size_t i = 0; i < nx; ++i) {
    for (std::size_t j = i; j < nx; ++j) hess.push_back(grad[i].diff(s.x[j]));
  }
  energy_ = make({H}, "H");
  gradient_ = make(grad, "gradH");
  hessian_ = make(hess, "the Hessian of H");
  std::vector<GiNaC::ex> z, dz, d2z;
  for (std::size_t k = 0; k < nw; ++k) {
    z.push_back(parse_expression(def_, "z", def_.dissipation[k], s.dissipation_table,
                                 "the port flows and parameters"));
    for (std::size_t l = 0; l < nw; ++l) dz.push_back(z[k].diff(s.w[l]));
    for (std::size_t l = 0; l < nw; ++l) {
      for (std::size_t m = l; m < nw; ++m) d2z.push_back(z[k].diff(s.w[l]).diff(s.w[m]));
    }
  }
  dissipation_ = make(z, "z");
  dissipation_jacobian_ = make(dz, "z'(w)");
  dissipation_second_ = make(d2z, "z''(w)");
  compile_defect(H, grad, hess);
  if (def_.control.design == ControlDesign::Design::kLimitCycle) compile_limit_cycle(z[0]);
}

// D(a, d) = H(a + d/2) - H(a - d/2) - gradH(a)^T d, expanded. When it is a
// polynomial in d (H polynomial in the states), every term is O(|d|^3) and
// the Gonzalez quotient D / |d|^2 has no cancellation (docs/METHOD.md §4).
void FileSystem::compile_defect(const GiNaC::ex& H, const std::vector<GiNaC::ex>& grad,
                                const std::vector<GiNaC::ex>& hess) {
  const Symbols& s = syms_;
  GiNaC::exmap plus, minus, at_a;
  GiNaC::lst d_list;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    plus[s.x[i]] = s.a[i] + s.d[i] / 2;
    minus[s.x[i]] = s.a[i] - s.d[i] / 2;
    at_a[s.x[i]] = s.a[i];
    d_list.append(s.d[i]);
  }
  GiNaC::ex D = H.subs(plus) - H.subs(minus);
  for (std::size_t i = 0; i < s.x.size(); ++i) D -= grad[i].subs(at_a) * s.d[i];
  D = D.expand();
  if (!D.is_polynomial(d_list)) return;  // the generic quotient with tau (PhSystem)
  if (D.is_zero()) {
    defect_is_zero_ = true;
    return;
  }
  // d D / d dx_j with a = x + dx/2, d = dx: dD/da_j / 2 + dD/dd_j. Both
  // bundles are written in the state symbols standing for the midpoint a,
  // so one evaluation gives gradH(a) and D (resp. H''(a), D and dD/d dx).
  GiNaC::exmap a_as_x;
  for (std::size_t i = 0; i < s.x.size(); ++i) a_as_x[s.a[i]] = s.x[i];
  std::vector<GiNaC::ex> dg = grad, jac = hess;
  dg.push_back(D.subs(a_as_x));
  jac.push_back(D.subs(a_as_x));
  for (std::size_t j = 0; j < s.x.size(); ++j) {
    jac.push_back((D.diff(s.a[j]) / 2 + D.diff(s.d[j])).subs(a_as_x));
  }
  gradient_and_defect_ = make(dg, "the Gonzalez defect of H");
  hessian_and_defect_ = make(jac, "the Gonzalez defect's gradient");
}

// Algorithm 4: z'(w) = c2 w^2 + c1 w + c0 < 0 between its roots (c2 > 0).
void FileSystem::compile_limit_cycle(const GiNaC::ex& z) {
  const Symbols& s = syms_;
  const int line = def_.line_of("control");
  GiNaC::exmap values;
  for (std::size_t i = 0; i < s.params.size(); ++i) {
    values[s.params[i]] = GiNaC::numeric(def_.parameters[i].second);
  }
  const GiNaC::ex dz = z.diff(s.w[0]).subs(values).expand();
  if (!dz.is_polynomial(s.w[0]) || dz.degree(s.w[0]) != 2) {
    throw SystemFileError(def_.file, line, "control.design = \"limit-cycle\" needs z(w) cubic in w "
                                           "(z' quadratic, as the paper's Algorithm 4); got z'(w) = " +
                                               to_c(dz) + "; use design = \"constant\"");
  }
  auto coeff = [&](int k) { return GiNaC::ex_to<GiNaC::numeric>(dz.coeff(s.w[0], k).evalf()).to_double(); };
  const double A = coeff(2), B = coeff(1), C = coeff(0);
  const double disc = B * B - 4.0 * A * C;
  if (!(A > 0.0 && disc > 0.0)) {
    throw SystemFileError(def_.file, line, "control.design = \"limit-cycle\": z'(w) = " + to_c(dz) +
                                               " is never negative, so there is no self-oscillation "
                                               "interval I_w; check z or use design = \"constant\"");
  }
  limit_cycle_ = stable_quadratic_roots(A, B, C);
  has_limit_cycle_ = true;
}

}  // namespace internal

std::string read_system_file_text(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    throw SystemFileError(path, 0, "cannot open the system file (no such file); check the path "
                                   "(relative paths in sweep files are relative to the sweep file)");
  }
  if (!S_ISREG(st.st_mode)) throw SystemFileError(path, 0, "not a regular file; pass a system file (.toml)");
  if (static_cast<std::size_t>(st.st_size) > kMaxSystemFileBytes) {
    throw SystemFileError(path, 0, "larger than " + std::to_string(kMaxSystemFileBytes) +
                                       " bytes; a system file is a page of TOML");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SystemFileError(path, 0, "cannot be read (permissions?)");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::unique_ptr<PhSystem> compile_system(const std::string& text, const std::string& file) {
  auto sys = std::make_unique<FileSystem>(parse_system_definition(text, file));
  if (sys->has_energy()) sys->check_energy_and_box();
  return sys;
}

std::unique_ptr<PhSystem> load_system_file(const std::string& path) {
  return compile_system(read_system_file_text(path), path);
}

}  // namespace phnn
