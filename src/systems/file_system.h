// src/systems/file_system.h — FileSystem, the PhSystem of a system file
// (private to src/systems): one variable buffer that every compiled
// expression (muParser bytecode of GiNaC's H, z and their derivatives)
// points into. Compiled in system_file.cpp; evaluated and checked in
// system_file_eval.cpp.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <ginac/ginac.h>

#include "phnn/systems/ph_system.h"
#include "phnn/systems/system_file.h"
#include "systems/expression_code.h"

namespace phnn {
namespace internal {

// Symbols of one system: states, parameters, ports, and the midpoint a and
// increment d of the closed-form Gonzalez defect.
struct Symbols {
  std::vector<GiNaC::realsymbol> x, params, w, a, d;
  std::vector<std::string> names;  // muParser variable order: x, params, w, a, d
  GiNaC::symtab energy_table, dissipation_table;
};

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

}  // namespace internal
}  // namespace phnn
