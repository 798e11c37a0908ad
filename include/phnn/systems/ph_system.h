// include/phnn/systems/ph_system.h — the n-dimensional port-Hamiltonian
// system interface (any n_x states, n_w dissipation ports, n_u inputs) that
// the general integrators and data generator use; built-in oscillators and
// system files both implement it. Physics only: no files, no Torch.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "phnn/common/enum_names.h"

namespace phnn {

/// The largest n_x + n_w + n_u (the size of S) a system may have. Vectors and
/// matrices of a system live on the stack up to this size (Eigen's
/// fixed-capacity dynamic types): the integrators' steps allocate nothing
/// (a heap allocation per temporary was half of a system file's DG step,
/// docs/BENCHMARKS.md). System files above it are refused where S is read.
constexpr int kMaxDimension = 32;
using VecX = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDimension, 1>;
using MatX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDimension, kMaxDimension>;

/// How the initial states x0 of a system's trajectories are drawn
/// (docs/METHOD.md "System files").
struct InitialConditionDesign {
  enum class Method {
    /// The paper's Algorithm 2 in any dimension: x ~ U(box) until
    /// H(x) lies in [energy_min, energy_max] (rejection).
    kEnergy,
    /// x ~ U(box), no condition on H.
    kBox,
    /// The paper's Algorithm 1 (n_x = 2, x = (q, p)): theta ~ U(0, 2 pi),
    /// r ~ U(energy_min, energy_max), E0 = sqrt(r) (or r with
    /// EnergySampling::kDirect), q = sqrt(2 E0 / H_qq(0)) sin(theta),
    /// p = sqrt(2 E0 / H_pp(0)) cos(theta).
    kAlgorithm1,
  };
  /// initial.method in a system file.
  static constexpr EnumNames<Method, 3> kMethodNames{
      "initial.method",
      {{{Method::kEnergy, "energy"}, {Method::kBox, "box"}, {Method::kAlgorithm1, "algorithm1"}}}};
  Method method = Method::kEnergy;
  double energy_min = 0.1;
  double energy_max = 1.0;
  /// One [lo, hi] per state (kEnergy, kBox). Empty with kEnergy: per state
  /// i, [-b_i, b_i] with b_i the largest |s| such that H(s e_i) <= energy_max
  /// (Algorithm 2's box for the Duffing oscillator).
  std::vector<std::array<double, 2>> box;
};

/// How the constant input u of a trajectory is drawn.
struct ControlDesign {
  enum class Design {
    /// u_i ~ U(range[i]) per input.
    kConstant,
    /// The paper's Algorithm 3 (n_x = 2, n_u = 1): E_eq ~ U(equilibrium
    /// energies), q* = +-s with H(s, 0) = E_eq (sign +-1 with equal
    /// probability), u = -dH/dq(q*, 0).
    kEnergyShaping,
    /// The paper's Algorithm 4 (n_w = n_u = 1, z polynomial with z'
    /// quadratic): w ~ U(I_w), I_w = {w : z'(w) < 0}, u = -w.
    kLimitCycle,
    /// Inputs that vary in time, held over each sample of the data (zero-
    /// order hold at the sample rate; docs/METHOD.md "Time-varying inputs"):
    /// u_i(t) = c_i + sum_k a_ik sin(2 pi f_k t + phi_ik), c_i ~ U(range[i])
    /// (0 without a range), a_ik ~ U(amplitude), phi_ik ~ U(0, 2 pi).
    kSines,
    /// u_i(t) = c_i + a_i sin(2 pi (f0 t + (f1 - f0) t^2 / (2 D)) + phi_i):
    /// a linear sweep from f0 to f1 over the trajectory's duration D.
    kChirp,
    /// u_i piecewise constant: a new level ~ U(range[i]) every `hold` seconds.
    kSteps,
  };
  /// control.design in a system file.
  static constexpr EnumNames<Design, 6> kDesignNames{
      "control.design",
      {{{Design::kConstant, "constant"}, {Design::kEnergyShaping, "energy-shaping"},
        {Design::kLimitCycle, "limit-cycle"}, {Design::kSines, "sines"}, {Design::kChirp, "chirp"},
        {Design::kSteps, "steps"}}}};
  Design design = Design::kConstant;
  std::vector<std::array<double, 2>> range;  // kConstant, kSteps: one per input; kSines/kChirp offsets
  double equilibrium_energy_min = 0.1;       // kEnergyShaping
  double equilibrium_energy_max = 1.0;
  std::vector<double> frequencies;           // kSines: f_k [Hz]; kChirp: {f0, f1}
  std::array<double, 2> amplitude = {0.0, 0.0};  // kSines, kChirp
  double hold = 0.1;                         // kSteps [s]
  bool time_varying() const {
    return design == Design::kSines || design == Design::kChirp || design == Design::kSteps;
  }
};

/// The port variables of eq:phs_S at one effort e (in place of gradH):
///   [x_dot; w; y] = S [e; z(w); u],  S = -S^T,  S_ww = 0 (w explicit).
struct PhFlows {
  VecX x_dot, w, z, y;
};

/// An n-dimensional port-Hamiltonian system (paper §3, eq:phs_S):
/// state x (n_x), dissipation flows w and efforts z(w) (n_w), inputs u and
/// outputs y (n_u). Rows and columns of S are ordered (x, w, u/y); S_ww = 0.
///
///   std::unique_ptr<PhSystem> sys = make_system("sweeps/systems/pendulum.toml");
///   VecX f = sys->vector_field(x, u);
///
/// Evaluation is not thread-safe for file-defined systems (their compiled
/// expressions share one variable buffer); use one object per thread.
class PhSystem {
 public:
  virtual ~PhSystem() = default;

  /// Name as given ("harmonic", a system file's `name`).
  virtual const std::string& name() const = 0;
  virtual const std::vector<std::string>& state_names() const = 0;
  virtual const std::vector<std::string>& state_units() const = 0;
  virtual const std::vector<std::string>& input_names() const = 0;
  int n_x() const { return static_cast<int>(state_names().size()); }
  int n_u() const { return static_cast<int>(input_names().size()); }
  int n_w() const { return static_cast<int>(S().rows()) - n_x() - n_u(); }

  /// False for a structure-only system file (no energy H): it describes
  /// measured data; hamiltonian(), the dissipation law and everything that
  /// generates data throw a SystemFileError saying so.
  virtual bool has_energy() const { return true; }
  virtual double hamiltonian(const VecX& x) const = 0;
  virtual VecX grad_hamiltonian(const VecX& x) const = 0;
  virtual MatX hessian(const VecX& x) const = 0;

  /// z(w) (n_w), dz/dw (n_w x n_w), and z''(w)[s, s] (n_w): the second
  /// derivative contracted twice with s (DG4's correction).
  virtual VecX dissipation(const VecX& w) const = 0;
  virtual MatX dissipation_jacobian(const VecX& w) const = 0;
  virtual VecX dissipation_second(const VecX& w, const VecX& s) const = 0;

  /// S of eq:phs_S, (n_x + n_w + n_u) square, skew-symmetric, S_ww = 0.
  virtual const MatX& S() const = 0;
  /// J of eq:phs_JR, (n_x + n_u) square, rows (x, y), columns (gradH, u).
  virtual const MatX& J() const = 0;

  /// Gonzalez discrete gradient (eq: gonzalez-discrete-gradient) and its
  /// Jacobian d dg / d dx (Newton). Default: the generic quotient with the
  /// min_dx_norm fallback (docs/METHOD.md §4); systems with a
  /// cancellation-free closed form override it.
  virtual VecX discrete_gradient(const VecX& x, const VecX& dx) const;
  virtual MatX discrete_gradient_jacobian(const VecX& x, const VecX& dx) const;

  /// How trajectories' x0 and u are drawn (the system file's [initial] and
  /// [control] tables; the built-in systems' Algorithms 1-4).
  virtual const InitialConditionDesign& initial_design() const = 0;
  virtual const ControlDesign& control_design() const = 0;
  /// Key of the system's random streams (CounterRng::for_trajectory): 0, 1,
  /// 2 for the paper's harmonic, duffing and self-sustained systems
  /// (built-in or file), a hash of the name otherwise.
  virtual int rng_id() const = 0;
  /// The system file's text ("" for a built-in system), stored in data and
  /// results files so a run can be reproduced from them alone.
  virtual const std::string& source_text() const = 0;
  /// Where errors about the energy or the designs point ("FILE:LINE" of the
  /// key, or the built-in's name).
  virtual std::string energy_location() const { return name(); }
  virtual std::string initial_location() const { return name(); }
  /// "FILE:LINE" of [control] or, given a key ("hold"), of that key.
  virtual std::string control_location(const std::string& key = "") const {
    (void)key;
    return name();
  }
  /// I_w = {w : z'(w) < 0} of Algorithm 4 (ControlDesign::kLimitCycle);
  /// throws std::invalid_argument where the system has none.
  virtual std::array<double, 2> self_oscillation_interval() const;
  /// Pairs of state indices for phase plots: a system file's [plots] phase,
  /// else (0,1), (2,3), ... (an odd last state paired with the first).
  virtual std::vector<std::array<int, 2>> phase_pairs() const;
  /// H [J] of the initial states of the figure trajectories (a system
  /// file's [plots] energies; the paper's 0.5 and 0.75 J for its three): x0 =
  /// s e_1 with H(s e_1) = E. Empty: the figures are inference trajectories.
  virtual const std::vector<double>& figure_energies() const {
    static const std::vector<double> none;
    return none;
  }

  /// Flows at effort e (in place of gradH) and input u.
  PhFlows flows(const VecX& effort, const VecX& u) const;
  /// The same, written into *out (the integrators' inner loops: no copies).
  void flows(const VecX& effort, const VecX& u, PhFlows* out) const;
  /// dF/de = S_xx + S_xw z'(w) S_wx (n_x x n_x), F = x_dot of flows().
  MatX flow_jacobian(const VecX& w) const;
  /// f(x, u) = flows(gradH(x), u).x_dot.
  VecX vector_field(const VecX& x, const VecX& u) const;

  /// Below this ||dx|| the generic Gonzalez quotient is dropped (tau,
  /// docs/METHOD.md §4).
  static constexpr double kMinDxNorm = 6e-6;

 private:
  /// The nonzero entries of S() row by row (columns ascending), built on
  /// first use: flows() sums only these (S is mostly zeros and ones).
  struct Couplings {
    int nx = 0, nw = 0, nu = 0;  // n_x(), n_w(), n_u() (virtual calls) once
    std::vector<int> start;  // row r: entries start[r] .. start[r + 1] - 1
    std::vector<int> column;
    std::vector<double> value;
  };
  const Couplings& couplings() const;
  /// flows() without y when `outputs` is false (vector_field needs x_dot).
  void port_flows(const VecX& effort, const VecX& u, bool outputs, PhFlows* out) const;
  mutable std::once_flag couplings_once_;
  mutable Couplings couplings_;
};

/// The rng_id of a system name: 0, 1, 2 for "harmonic", "duffing",
/// "self-sustained"; else 3 + (FNV-1a 64 of the name mod 2^31 - 3).
int system_rng_id(const std::string& name);

/// A system by name or by path: "harmonic", "duffing", "self-sustained"
/// (built-in), the name of a shipped system file ("pendulum": below), or a
/// system file (an argument ending in ".toml" or containing '/'), relative
/// paths resolved against `base_dir` when it is not empty. Throws
/// SystemFileError (FILE:LINE and the fix) for a bad file,
/// std::invalid_argument for an unknown name.
std::unique_ptr<PhSystem> make_system(const std::string& name_or_path,
                                      const std::string& base_dir = "");
/// What to do about H = `found` < 0 at a drawn state, for the errors that
/// find one: why phnn needs H >= 0 and the constant that lifts H above 0
/// over `box` (H's smallest value on a grid of <= 4 096 points of it, and
/// `found`, rounded up to two significant digits), e.g. "; phnn draws ...:
/// add a constant C >= 0.16 to H (...), or shrink initial.box".
std::string negative_energy_advice(const PhSystem& system,
                                   const std::vector<std::array<double, 2>>& box, double found);

/// True when make_system would read `name_or_path` as a file (a path, or
/// a shipped system file's name).
bool is_system_file_argument(const std::string& name_or_path);

/// The directory of the shipped system files: $PHNN_SYSTEMS_DIR when set;
/// else, from the running binary's directory BIN, the first of
/// BIN/../share/phnn/systems (an installation) and BIN/../sweeps/systems (a
/// build directory inside the source tree) that exists; else the source
/// tree's sweeps/systems compiled in.
std::string shipped_systems_dir();
/// The shipped file a bare name stands for (`name` made of letters, digits,
/// '-' and '_', not a built-in name, and NAME.toml present in
/// shipped_systems_dir()), else "".
std::string shipped_system_path(const std::string& name);
/// The file to read for a system argument: a shipped file's path for its
/// name, else the argument itself.
std::string system_file_path(const std::string& name_or_path);

}  // namespace phnn
