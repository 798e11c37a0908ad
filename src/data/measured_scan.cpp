// src/data/measured_scan.cpp — the checks every split of recorded
// trajectories makes, the first pass that keeps what a split needs of each
// trajectory (RecordingScan), and the pieces that copy pairs and inference
// windows as trajectories pass by (src/data/measured_checks.h). In memory
// only; touches nothing but its arguments.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "data/measured_checks.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {

void fail(const std::string& message) { throw MeasuredDataError(message); }

std::string g(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

// Shapes, finite values, >= 2 samples, increasing time.
void check_trajectory(const MeasuredTrajectory& m, int nx, int nu) {
  const std::size_t n = m.size();
  PHNN_CHECK(m.n_x == nx && m.n_u == nu && m.x.size() == n * static_cast<std::size_t>(nx) &&
                 m.u.size() == n * static_cast<std::size_t>(nu),
             "ragged trajectory from the reader");
  if (n < 2) {
    fail(m.where(0) + " has " + std::to_string(n) + " sample; a training pair (x_n, x_n+1) needs "
         "at least 2: drop it or record longer");
  }
  const auto finite = [](const double* v, int count) {
    return std::all_of(v, v + count, [](double a) { return std::isfinite(a); });
  };
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(m.t[k]) || !finite(m.x.data() + k * static_cast<std::size_t>(nx), nx) ||
        !finite(m.u.data() + k * static_cast<std::size_t>(nu), nu)) {
      fail(m.where(k) + ": a value is NaN or infinite; remove "
           "or repair the sample (phnn needs every state and input finite)");
    }
    if (k > 0 && !(m.t[k] > m.t[k - 1])) {
      fail(m.where(k) + ": t = " + g(m.t[k]) +
           " does not increase (previous " + g(m.t[k - 1]) + "); sort the samples by time");
    }
  }
}

// Every step within tol h of the median step (a gap or one bad stamp cannot
// shift the reference), then h = (t_N-1 - t_0) / (N - 1), the most accurate
// estimate once uniform.
double uniform_step(const MeasuredTrajectory& m, double tolerance) {
  std::vector<double> steps;
  for (std::size_t k = 1; k < m.t.size(); ++k) steps.push_back(m.t[k] - m.t[k - 1]);
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (std::size_t k = 1; k < m.t.size(); ++k) {
    const double dt = steps[k - 1];
    if (std::abs(dt - median) > tolerance * median) {
      fail(m.where(k) + ": t jumps by " + g(dt) + " s where the trajectory's step is " + g(median) +
           " s (" + (dt > 1.5 * median ? "a gap" : "jitter") +
           "); phnn needs uniform sampling: resample the recording or split it at the gap");
    }
  }
  return (m.t.back() - m.t.front()) / static_cast<double>(m.t.size() - 1);
}

void RecordingScan::add(const MeasuredTrajectory& m) {
  PHNN_CHECK(all_.size() < std::numeric_limits<std::uint32_t>::max(), "too many trajectories");
  if (m.size() > std::numeric_limits<std::uint32_t>::max()) {
    fail(m.where(0) + " has " + std::to_string(m.size()) + " samples; phnn import takes at most " +
         std::to_string(std::numeric_limits<std::uint32_t>::max()) + " per trajectory: split it");
  }
  ScannedTrajectory s;
  s.id = m.id;
  s.samples = static_cast<std::uint32_t>(m.size());
  s.line = m.line.empty() ? -1 : m.line[0];
  if (sources_.empty() || sources_.back().second != m.source) sources_.emplace_back(all_.size(), m.source);
  try {
    check_trajectory(m, nx_, nu_);
    try {
      s.h = uniform_step(m, tolerance_);
    } catch (const MeasuredDataError& e) {
      step_errors_.emplace(all_.size(), e.what());
    }
  } catch (const MeasuredDataError& e) {
    if (check_error_.empty()) check_error_ = e.what();
  }
  all_.push_back(s);
}

std::string RecordingScan::where(std::size_t i) const {
  const ScannedTrajectory& s = all_[i];
  const auto run = std::upper_bound(sources_.begin(), sources_.end(), i,
                                    [](std::size_t k, const auto& r) { return k < r.first; }) - 1;
  return run->second + (s.line >= 0 ? ":" + std::to_string(s.line) : std::string()) +
         ": trajectory " + std::to_string(s.id);
}

void RecordingScan::throw_check_error() const {
  if (!check_error_.empty()) fail(check_error_);
}

std::vector<std::uint32_t> RecordingScan::sorted_by_id() const {
  std::vector<std::uint32_t> order(all_.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return all_[a].id < all_[b].id; });
  for (std::size_t i = 1; i < order.size(); ++i) {
    if (all_[order[i]].id == all_[order[i - 1]].id) {
      fail(where(order[i]) + " was already read at " + where(order[i - 1]) +
           " (a trajectory's rows must be contiguous and its id unique); give each trajectory "
           "its own id");
    }
  }
  return order;
}

double RecordingScan::common_step(const std::vector<std::uint32_t>& order, const ImportOptions& o,
                                  std::string* summary) const {
  PHNN_CHECK(!order.empty(), "common_step of no trajectory");
  const std::uint32_t first = order[0];
  const double h0 = all_[first].h;
  for (const std::uint32_t i : order) {
    const auto bad = step_errors_.find(i);
    if (bad != step_errors_.end()) fail(bad->second);
    const double h = all_[i].h;
    if (std::abs(h - h0) > o.time_tolerance * h0) {
      fail(where(i) + " is sampled every " + g(h) + " s, " + where(first) + " every " + g(h0) +
           " s; phnn needs one sampling rate: resample one of them");
    }
  }
  if (o.sample_rate > 0) {
    if (std::abs(h0 * o.sample_rate - 1.0) > o.time_tolerance) {
      fail("--sample-rate " + g(o.sample_rate) + " Hz disagrees with the time column (" +
           where(first) + " is sampled at " + g(1.0 / h0) + " Hz); drop --sample-rate or fix t");
    }
    if (summary) *summary += "sample rate " + g(o.sample_rate) + " Hz (given)\n";
    return 1.0 / o.sample_rate;
  }
  const double rate = 1.0 / h0, whole = std::round(rate);
  if (whole >= 1 && std::abs(rate - whole) <= 1e-9 * rate) {
    if (summary) *summary += "sample rate " + g(whole) + " Hz (from t)\n";
    return 1.0 / whole;
  }
  if (summary) *summary += "sample rate " + g(rate) + " Hz (from t, not an integer)\n";
  return h0;
}

void RecordingScan::check_same(std::size_t i, const MeasuredTrajectory& m) const {
  if (i >= all_.size() || all_[i].id != m.id || all_[i].samples != m.size()) {
    fail(m.where(0) + " (" + std::to_string(m.size()) + " samples) is not what the first pass "
         "over the recordings read there" + (i < all_.size() ? " (" + where(i) + ", " +
         std::to_string(all_[i].samples) + " samples)" : std::string(" (nothing)")) +
         "; did a file change while phnn import read it? Import it again");
  }
}

void RecordingScan::check_all_seen(std::size_t count) const {
  if (count != all_.size()) {
    fail("the second pass over the recordings read " + std::to_string(count) + " trajectories, "
         "the first " + std::to_string(all_.size()) + "; did a file change while phnn import read "
         "it? Import it again");
  }
}

std::vector<std::uint32_t> inverse(const std::vector<std::uint32_t>& order) {
  std::vector<std::uint32_t> out(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) out[order[k]] = static_cast<std::uint32_t>(k);
  return out;
}

WindowCollector::WindowCollector(int nx, int nu, std::size_t count, std::size_t w, bool positions,
                                 double step)
    : rows_(nx, nu, count, w, /*per_sample_inputs=*/true, positions) {
  rows_.step = step;
}

void WindowCollector::add(std::size_t q, const MeasuredTrajectory& m, std::size_t start) {
  const auto nx = static_cast<std::size_t>(rows_.n_x), nu = static_cast<std::size_t>(rows_.n_u);
  const std::size_t w = rows_.samples;
  rows_.trajectory[q] = m.id;
  if (!rows_.position.empty()) rows_.position[q] = static_cast<std::int64_t>(start);
  const auto u0 = m.u.begin() + static_cast<long>(start * nu);
  std::copy(u0, u0 + static_cast<long>(nu), rows_.u.begin() + static_cast<long>(q * nu));
  std::copy(u0, u0 + static_cast<long>(w * nu), rows_.inputs.begin() + static_cast<long>(q * w * nu));
  const auto x0 = m.x.begin() + static_cast<long>(start * nx);
  std::copy(x0, x0 + static_cast<long>(w * nx), rows_.states.begin() + static_cast<long>(q * w * nx));
  for (std::size_t k = start + 1; k < start + w && !varying_; ++k) varying_ = !m.same_input(k, start);
}

PhInferenceRows WindowCollector::finish() {
  if (!varying_) std::vector<double>().swap(rows_.inputs);
  return std::move(rows_);
}

void record_timing(DatasetOptions* o, std::uint64_t data_seed, double h, std::size_t samples) {
  o->data_seed = data_seed;
  o->sample_rate = 1.0 / h;
  o->generation_step = h;
  o->period = 1.0;
  o->beta = h * static_cast<double>(samples - 1);
}

void set_pair(PhPairRows* rows, std::size_t i, const MeasuredTrajectory& m, std::size_t n) {
  const auto nx = static_cast<std::size_t>(m.n_x), nu = static_cast<std::size_t>(m.n_u);
  rows->set(i, m.id, static_cast<std::int64_t>(n), m.x.data() + n * nx, m.x.data() + (n + 1) * nx,
            m.u.data() + n * nu);
}

}  // namespace internal
}  // namespace phnn
