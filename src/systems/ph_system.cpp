// src/systems/ph_system.cpp — the PhSystem interface's shared parts (flows,
// the generic Gonzalez discrete gradient) and the registry make_system()
// (built-in names, whose shipped files builtin_systems.h reads, and system
// files).
#include "phnn/systems/ph_system.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "phnn/systems/builtin_systems.h"
#include "phnn/systems/system_file.h"

namespace phnn {

// flows() and flow_jacobian() are written as loops over S: these systems
// are small and S is sparse, and dynamic-size block products would allocate
// per call.
const PhSystem::Couplings& PhSystem::couplings() const {
  std::call_once(couplings_once_, [this] {
    const MatX& s = S();
    couplings_.nx = n_x();
    couplings_.nw = n_w();
    couplings_.nu = n_u();
    couplings_.start.push_back(0);
    for (int r = 0; r < s.rows(); ++r) {
      for (int c = 0; c < s.cols(); ++c) {
        if (s(r, c) == 0.0) continue;
        couplings_.column.push_back(c);
        couplings_.value.push_back(s(r, c));
      }
      couplings_.start.push_back(static_cast<int>(couplings_.column.size()));
    }
  });
  return couplings_;
}

PhFlows PhSystem::flows(const VecX& effort, const VecX& u) const {
  PhFlows out;
  port_flows(effort, u, true, &out);
  return out;
}

void PhSystem::flows(const VecX& effort, const VecX& u, PhFlows* out) const {
  port_flows(effort, u, true, out);
}

// Each row of [x_dot; w; y] = S [e; z; u] sums its nonzero couplings in
// column order: for finite operands the same bits as the dense row
// (acc + (+-0) = acc, and acc is never -0), at a fraction of the work.
void PhSystem::port_flows(const VecX& effort, const VecX& u, bool outputs, PhFlows* out) const {
  const Couplings& c = couplings();
  const int nx = c.nx, nw = c.nw, nu = c.nu;
  const int* start = c.start.data();
  const int* column = c.column.data();
  const double* value = c.value.data();
  double operand[kMaxDimension];  // [e; z; u]
  for (int j = 0; j < nx; ++j) operand[j] = effort(j);
  for (int j = 0; j < nu; ++j) operand[nx + nw + j] = u(j);
  auto row = [&](int r) {
    double acc = 0.0;
    for (int k = start[r]; k < start[r + 1]; ++k) acc += value[k] * operand[column[k]];
    return acc;
  };
  // S_ww = 0: w depends on the effort and u only.
  out->w.resize(nw);
  for (int k = 0; k < nw; ++k) out->w(k) = row(nx + k);
  if (nw > 0)
    out->z = dissipation(out->w);
  else
    out->z.resize(0);
  for (int j = 0; j < nw; ++j) operand[nx + j] = out->z(j);
  out->x_dot.resize(nx);
  for (int i = 0; i < nx; ++i) out->x_dot(i) = row(i);
  out->y.resize(outputs ? nu : 0);
  for (int k = 0; k < out->y.size(); ++k) out->y(k) = row(nx + nw + k);
}

MatX PhSystem::flow_jacobian(const VecX& w) const {
  const Couplings& c = couplings();
  const int nx = c.nx, nw = c.nw;
  const MatX& s = S();
  MatX jac = s.topLeftCorner(nx, nx);
  if (nw == 0) return jac;
  const MatX dz = dissipation_jacobian(w);
  for (int i = 0; i < nx; ++i) {
    for (int k = 0; k < nw; ++k) {
      if (s(i, nx + k) == 0.0) continue;
      for (int l = 0; l < nw; ++l) {
        if (dz(k, l) == 0.0) continue;
        for (int j = 0; j < nx; ++j) jac(i, j) += s(i, nx + k) * dz(k, l) * s(nx + l, j);
      }
    }
  }
  return jac;
}

VecX PhSystem::vector_field(const VecX& x, const VecX& u) const {
  PhFlows f;
  port_flows(grad_hamiltonian(x), u, false, &f);
  return f.x_dot;
}

// dg(x, dx) = gradH(m) + D / |dx|^2 dx,  m = x + dx/2,
// D = H(x + dx) - H(x) - gradH(m)^T dx  (= gradH(m) below tau).
VecX PhSystem::discrete_gradient(const VecX& x, const VecX& dx) const {
  const VecX mid = x + 0.5 * dx;
  VecX g = grad_hamiltonian(mid);
  const double n2 = dx.squaredNorm();
  if (!(std::sqrt(n2) >= kMinDxNorm) || n2 == 0.0) return g;
  const double defect = hamiltonian(x + dx) - hamiltonian(x) - g.dot(dx);
  g += (defect / n2) * dx;
  return g;
}

// d dg / d dx = H''(m)/2 + (D/n2) I + dx (dD/d dx / n2 - 2 D dx / n2^2)^T,
// dD/d dx = gradH(x + dx) - gradH(m) - H''(m) dx / 2.
MatX PhSystem::discrete_gradient_jacobian(const VecX& x, const VecX& dx) const {
  const VecX mid = x + 0.5 * dx;
  const MatX hess = hessian(mid);
  MatX jac = 0.5 * hess;
  const double n2 = dx.squaredNorm();
  if (!(std::sqrt(n2) >= kMinDxNorm) || n2 == 0.0) return jac;
  const VecX g = grad_hamiltonian(mid);
  const double defect = hamiltonian(x + dx) - hamiltonian(x) - g.dot(dx);
  const VecX d_defect = grad_hamiltonian(x + dx) - g - 0.5 * (hess * dx);
  jac.diagonal().array() += defect / n2;
  jac += dx * (d_defect / n2 - (2.0 * defect / (n2 * n2)) * dx).transpose();
  return jac;
}

std::array<double, 2> PhSystem::self_oscillation_interval() const {
  throw std::invalid_argument(name() +
                              ": no self-oscillation interval I_w = {w : z'(w) < 0}; "
                              "the limit-cycle design needs one port with a polynomial z(w) "
                              "whose z' is quadratic and negative between two roots");
}

std::vector<std::array<int, 2>> PhSystem::phase_pairs() const {
  std::vector<std::array<int, 2>> pairs;
  for (int i = 0; i + 1 < n_x(); i += 2) pairs.push_back({i, i + 1});
  if (n_x() % 2 == 1) pairs.push_back({n_x() - 1, 0});
  return pairs;
}

int system_rng_id(const std::string& name) {
  for (SystemKind kind : all_systems()) {
    if (name == to_string(kind)) return static_cast<int>(kind);
  }
  std::uint64_t hash = 0xcbf29ce484222325ULL;  // FNV-1a 64
  for (unsigned char c : name) {
    hash ^= c;
    hash *= 0x100000001b3ULL;
  }
  return 3 + static_cast<int>(hash % 0x7FFFFFFCULL);
}

namespace {

bool is_path_argument(const std::string& s) {
  const std::string ext = ".toml";
  return s.find('/') != std::string::npos ||
         (s.size() > ext.size() && s.compare(s.size() - ext.size(), ext.size(), ext) == 0);
}

bool is_directory(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

// The running binary's directory ("" when /proc/self/exe cannot be read).
std::string binary_dir() {
  std::string buf(4096, '\0');
  const ssize_t n = ::readlink("/proc/self/exe", buf.data(), buf.size() - 1);
  if (n <= 0) return "";
  buf.resize(static_cast<std::size_t>(n));
  const std::size_t slash = buf.rfind('/');
  return slash == std::string::npos ? "" : buf.substr(0, slash);
}

}  // namespace

std::string shipped_systems_dir() {
  if (const char* env = std::getenv("PHNN_SYSTEMS_DIR"); env != nullptr && *env != '\0') return env;
  const std::string bin = binary_dir();
  if (!bin.empty()) {
    for (const char* rel : {"/../share/phnn/systems", "/../sweeps/systems"}) {
      if (is_directory(bin + rel)) return bin + rel;
    }
  }
  return PHNN_SHIPPED_SYSTEMS_DIR;
}

std::string shipped_system_path(const std::string& name) {
  if (name.empty() || is_path_argument(name)) return "";
  for (const char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') return "";
  }
  for (const SystemKind kind : all_systems()) {
    if (to_string(kind) == name) return "";
  }
  const std::string path = shipped_systems_dir() + "/" + name + ".toml";
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) ? path : "";
}

std::string system_file_path(const std::string& name_or_path) {
  const std::string shipped = shipped_system_path(name_or_path);
  return shipped.empty() ? name_or_path : shipped;
}

namespace {

// min H on a grid of k^n <= 4096 points of `box` (n <= 12; else +inf).
double grid_minimum(const PhSystem& system, const std::vector<std::array<double, 2>>& box) {
  const int n = static_cast<int>(box.size());
  if (n == 0 || n > 12) return std::numeric_limits<double>::infinity();
  int k = 2;
  while (std::pow(k + 1, n) <= 4096) ++k;
  long total = 1;
  for (int i = 0; i < n; ++i) total *= k;
  double lowest = std::numeric_limits<double>::infinity();
  VecX x(n);
  for (long c = 0; c < total; ++c) {
    long rest = c;
    for (int i = 0; i < n; ++i, rest /= k) {
      const auto& [lo, hi] = box[static_cast<std::size_t>(i)];
      x(i) = lo + (hi - lo) * static_cast<double>(rest % k) / (k - 1);
    }
    const double h = system.hamiltonian(x);
    if (std::isfinite(h)) lowest = std::min(lowest, h);
  }
  return lowest;
}

}  // namespace

std::string negative_energy_advice(const PhSystem& system,
                                   const std::vector<std::array<double, 2>>& box, double found) {
  const double lowest = std::min(found, grid_minimum(system, box));
  const double unit = std::pow(10.0, std::floor(std::log10(-lowest)) - 1);
  const double c = std::ceil(-lowest / unit) * unit;
  std::ostringstream os;
  os << "; phnn draws initial states by their energy in [E_min, E_max] >= 0 and reads energies "
        "from 0, so H must be >= 0 where states are drawn. A constant changes no trajectory (only "
        "grad H enters the dynamics): add a constant C >= "
     << std::setprecision(2) << c << " to H (the smallest H on a grid of the initial box is "
     << std::setprecision(6) << lowest << "), or shrink initial.box";
  return os.str();
}

bool is_system_file_argument(const std::string& s) {
  return is_path_argument(s) || !shipped_system_path(s).empty();
}

std::unique_ptr<PhSystem> make_system(const std::string& name_or_path,
                                      const std::string& base_dir) {
  const std::string shipped = shipped_system_path(name_or_path);
  if (!shipped.empty()) return load_system_file(shipped);
  if (!is_path_argument(name_or_path)) {
    SystemKind kind;
    try {
      kind = parse_system(name_or_path);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(e.what()) + " (shipped system files are read from " +
                                  shipped_systems_dir() + ")");
    }
    return builtin_system(OscillatorOptions::defaults(kind), BuiltinEnergies{});
  }
  std::string path = name_or_path;
  if (!base_dir.empty() && !path.empty() && path[0] != '/') path = base_dir + "/" + path;
  return load_system_file(path);
}

}  // namespace phnn
