// src/systems/system_file.cpp — a system file compiled into a PhSystem:
// GiNaC parses H and z(w) and differentiates them (gradH, the Hessian, z',
// z'', and the Gonzalez defect in closed form when it is a polynomial);
// muParser compiles the results to bytecode for fast evaluation. Reads the
// system file; writes nothing.
// Size: one class around one variable buffer that every compiled expression
// points into: its compilation, evaluation and the checks that evaluate it.
#include "phnn/systems/system_file.h"

#include "phnn/systems/oscillators.h"
#include "systems/expression_bounds.h"
#include "systems/expression_code.h"

#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <ginac/ginac.h>
#include <muParser.h>

namespace phnn {
namespace {

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

// Symbols of one system: states, parameters, ports, and the midpoint a and
// increment d of the closed-form Gonzalez defect.
struct Symbols {
  std::vector<GiNaC::realsymbol> x, params, w, a, d;
  std::vector<std::string> names;  // muParser variable order: x, params, w, a, d
  GiNaC::symtab energy_table, dissipation_table;
};

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

class FileSystem : public PhSystem {
 public:
  explicit FileSystem(SystemDefinition def);
  FileSystem(const FileSystem&) = delete;
  FileSystem& operator=(const FileSystem&) = delete;

  const std::string& name() const override { return def_.name; }
  const std::vector<std::string>& state_names() const override { return def_.states; }
  const std::vector<std::string>& state_units() const override { return def_.state_units; }
  const std::vector<std::string>& input_names() const override { return def_.inputs; }
  bool has_energy() const override { return def_.has_energy(); }
  double hamiltonian(const VecX& x) const override {
    need_energy();
    set_states(x);
    return *energy_->eval();
  }
  VecX grad_hamiltonian(const VecX& x) const override {
    need_energy();
    set_states(x);
    return Eigen::Map<const VecX>(gradient_->eval(), n_x());
  }
  MatX hessian(const VecX& x) const override;
  VecX dissipation(const VecX& w) const override {
    need_energy();
    if (n_w() == 0) return VecX(0);
    set_ports(w);
    return Eigen::Map<const VecX>(dissipation_->eval(), n_w());
  }
  MatX dissipation_jacobian(const VecX& w) const override {
    need_energy();
    if (n_w() == 0) return MatX(0, 0);
    set_ports(w);
    return Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(
        dissipation_jacobian_->eval(), n_w(), n_w());
  }
  VecX dissipation_second(const VecX& w, const VecX& s) const override;
  const MatX& S() const override { return def_.S; }
  const MatX& J() const override { return def_.J; }
  VecX discrete_gradient(const VecX& x, const VecX& dx) const override;
  MatX discrete_gradient_jacobian(const VecX& x, const VecX& dx) const override;
  const InitialConditionDesign& initial_design() const override { return def_.initial; }
  const ControlDesign& control_design() const override { return def_.control; }
  int rng_id() const override { return system_rng_id(def_.name); }
  const std::string& source_text() const override { return def_.text; }
  std::string energy_location() const override { return location("H"); }
  std::string initial_location() const override { return location("initial"); }
  std::string control_location(const std::string& key = "") const override {
    const std::string full = "control." + key;
    return location(!key.empty() && def_.lines.count(full) ? full : "control");
  }
  std::array<double, 2> self_oscillation_interval() const override;
  std::vector<std::array<int, 2>> phase_pairs() const override {
    return def_.phase_pairs.empty() ? PhSystem::phase_pairs() : def_.phase_pairs;
  }
  const std::vector<double>& figure_energies() const override { return def_.figure_energies; }

  /// Resolves the automatic box of initial.method = "energy" and checks H
  /// at the box's centre, axis ends and corners (finite, >= 0).
  void check_energy_and_box();
  /// H finite and >= 0 at each point, else an error at the file's H.
  void check_energy_at(const std::vector<VecX>& points) const;

 private:
  // A structure-only file generates nothing: its energy and dissipation
  // law are not defined.
  void need_energy() const {
    if (def_.has_energy()) return;
    throw SystemFileError(def_.file, def_.line_of("name"),
                          "system \"" + def_.name + "\" defines no energy H (a structure-only "
                          "file): it can describe measured data (phnn import, then --data or "
                          "data = [...]) but cannot generate any; add H, z, [initial] and "
                          "[control] to generate data");
  }
  std::string location(const std::string& key) const {
    return def_.file + ":" + std::to_string(def_.line_of(key));
  }
  void compile();
  void compile_defect(const GiNaC::ex& H, const std::vector<GiNaC::ex>& grad,
                      const std::vector<GiNaC::ex>& hess);
  void compile_limit_cycle(const GiNaC::ex& z);
  void set_states(const VecX& x) const {
    for (int i = 0; i < n_x(); ++i) vars_[static_cast<std::size_t>(i)] = x(i);
  }
  void set_midpoint_and_increment(const VecX& x, const VecX& dx) const {
    for (int i = 0; i < n_x(); ++i) {
      vars_[static_cast<std::size_t>(i)] = x(i) + 0.5 * dx(i);
      vars_[d_offset_ + static_cast<std::size_t>(i)] = dx(i);
    }
  }
  void set_ports(const VecX& w) const {
    for (int i = 0; i < n_w(); ++i) vars_[w_offset_ + static_cast<std::size_t>(i)] = w(i);
  }
  std::unique_ptr<CompiledExpressions> make(const std::vector<GiNaC::ex>& exprs,
                                            const std::string& what) const;

  SystemDefinition def_;
  Symbols syms_;  // one set: GiNaC symbols of equal names are still distinct
  // Each parameter's exact value (the rational its double stands for):
  // substituted before compiling, so GiNaC folds products of parameters and
  // numbers exactly (k3/4, 1/m) and muParser evaluates one constant each.
  GiNaC::exmap parameter_values_;
  std::unique_ptr<double[]> vars_;
  std::size_t w_offset_ = 0, d_offset_ = 0;
  std::unique_ptr<CompiledExpressions> energy_, gradient_, hessian_, dissipation_,
      dissipation_jacobian_, dissipation_second_, gradient_and_defect_, hessian_and_defect_;
  bool defect_is_zero_ = false;
  bool has_limit_cycle_ = false;
  std::array<double, 2> limit_cycle_ = {0.0, 0.0};
};

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

std::array<double, 2> FileSystem::self_oscillation_interval() const {
  if (!has_limit_cycle_) return PhSystem::self_oscillation_interval();
  return limit_cycle_;
}

MatX FileSystem::hessian(const VecX& x) const {
  need_energy();
  set_states(x);
  const double* v = hessian_->eval();
  MatX h(n_x(), n_x());
  for (int i = 0, k = 0; i < n_x(); ++i) {
    for (int j = i; j < n_x(); ++j, ++k) h(i, j) = h(j, i) = v[k];
  }
  return h;
}

VecX FileSystem::dissipation_second(const VecX& w, const VecX& s) const {
  need_energy();
  const int nw = n_w();
  VecX out = VecX::Zero(nw);
  if (nw == 0) return out;
  set_ports(w);
  const double* v = dissipation_second_->eval();
  for (int k = 0, idx = 0; k < nw; ++k) {
    for (int l = 0; l < nw; ++l) {
      for (int m = l; m < nw; ++m, ++idx) out(k) += (l == m ? 1.0 : 2.0) * v[idx] * s(l) * s(m);
    }
  }
  return out;
}

VecX FileSystem::discrete_gradient(const VecX& x, const VecX& dx) const {
  need_energy();
  if (!defect_is_zero_ && !gradient_and_defect_) return PhSystem::discrete_gradient(x, dx);
  const int n = n_x();
  const double n2 = dx.squaredNorm();
  if (defect_is_zero_ || n2 == 0.0) return grad_hamiltonian(x + 0.5 * dx);
  set_midpoint_and_increment(x, dx);
  const double* v = gradient_and_defect_->eval();
  VecX g(n);
  for (int i = 0; i < n; ++i) g(i) = v[i] + (v[n] / n2) * dx(i);
  return g;
}

MatX FileSystem::discrete_gradient_jacobian(const VecX& x, const VecX& dx) const {
  need_energy();
  if (!defect_is_zero_ && !hessian_and_defect_) return PhSystem::discrete_gradient_jacobian(x, dx);
  const double n2 = dx.squaredNorm();
  if (defect_is_zero_ || n2 == 0.0) return 0.5 * hessian(x + 0.5 * dx);
  const int n = n_x();
  set_midpoint_and_increment(x, dx);
  const double* v = hessian_and_defect_->eval();
  const int m = n * (n + 1) / 2;
  const double D = v[m];
  MatX jac(n, n);
  for (int i = 0, k = 0; i < n; ++i) {
    for (int j = i; j < n; ++j, ++k) jac(i, j) = jac(j, i) = 0.5 * v[k];
  }
  // + (D/n2) I + dx (dD/n2 - 2 D dx / n2^2)^T
  for (int i = 0; i < n; ++i) {
    jac(i, i) += D / n2;
    for (int j = 0; j < n; ++j) {
      jac(i, j) += dx(i) * (v[m + 1 + j] / n2 - 2.0 * D * dx(j) / (n2 * n2));
    }
  }
  return jac;
}

// Largest s with H(s e) <= e_max along direction e (bisection after
// doubling); < 0 when H stays below e_max up to |s| = 1e6.
double axis_bound(const PhSystem& sys, const VecX& e, double e_max) {
  double hi = 1e-3;
  while (!(sys.hamiltonian(hi * e) > e_max)) {
    hi *= 2.0;
    if (hi > 1e6) return -1.0;
  }
  double lo = 0.0;
  for (int it = 0; it < 200 && lo < hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (sys.hamiltonian(mid * e) > e_max ? hi : lo) = mid;
  }
  return lo;
}

void FileSystem::check_energy_and_box() {
  InitialConditionDesign& d = def_.initial;
  const int nx = n_x();
  check_energy_at({VecX::Zero(nx)});
  if (d.method == InitialConditionDesign::Method::kEnergy && d.box.empty()) {
    for (int i = 0; i < nx; ++i) {
      VecX e = VecX::Zero(nx);
      e(i) = 1.0;
      const double b = std::max(axis_bound(*this, e, d.energy_max), axis_bound(*this, -e, d.energy_max));
      if (!(b > 0.0)) {
        throw SystemFileError(def_.file, def_.line_of("initial"),
                              "cannot bound state \"" + def_.states[static_cast<std::size_t>(i)] +
                                  "\" for initial.method = \"energy\": H along it stays below "
                                  "energy_max = " + std::to_string(d.energy_max) +
                                  " (or is not finite); give initial.box = [[lo, hi], ...]");
      }
      d.box.push_back({-b, b});
    }
  }
  if (d.method == InitialConditionDesign::Method::kAlgorithm1) {
    const MatX h0 = hessian(VecX::Zero(nx));
    if (!(h0(0, 0) > 0.0 && h0(1, 1) > 0.0 && std::isfinite(h0(0, 0)) && std::isfinite(h0(1, 1)))) {
      throw SystemFileError(def_.file, def_.line_of("initial"),
                            "initial.method = \"algorithm1\" needs d2H/dq2 > 0 and d2H/dp2 > 0 at "
                            "x = 0 (an ellipse around the origin); use \"energy\" or \"box\"");
    }
  }
  // H at the box's (up to 2^10) corners.
  std::vector<VecX> points;
  if (!d.box.empty()) {
    const int corners = nx <= 10 ? 1 << nx : 0;
    for (int c = 0; c < corners; ++c) {
      VecX p(nx);
      for (int i = 0; i < nx; ++i) p(i) = d.box[static_cast<std::size_t>(i)][(c >> i) & 1];
      points.push_back(p);
    }
  }
  check_energy_at(points);
}

void FileSystem::check_energy_at(const std::vector<VecX>& points) const {
  for (const VecX& p : points) {
    const double h = hamiltonian(p);
    if (!std::isfinite(h) || h < 0.0) {
      std::ostringstream os;
      os << "H = " << h << " at x = (" << p.transpose().format(kRow) << ")" << (std::isfinite(h) ? " is negative" : " is not finite");
      if (std::isfinite(h)) {
        os << negative_energy_advice(*this, def_.initial.box, h);
      } else {
        os << "; an energy must be finite wherever initial states are drawn: fix H or shrink initial.box";
      }
      throw SystemFileError(def_.file, def_.line_of("H"), os.str());
    }
  }
}

}  // namespace

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
