// src/report/comparison.cpp — compare_cells: per-seed log ratios or the
// Hodges-Lehmann shift, P(A < B), their intervals and the four-way reading;
// the pairing condition on two run configurations.
#include "phnn/report/comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

namespace phnn {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// log10 of an MSE; NaN and +inf (diverged) are +inf.
double log_mse(double mse) { return std::isnan(mse) ? kInf : std::log10(mse); }

// x - y with two equal infinities a tie (0), never NaN.
double log_difference(double x, double y) { return x == y ? 0.0 : x - y; }

void read(const Interval& effect, double margin, bool enough, Comparison* c) {
  if (!enough) {
    c->reading = ComparisonReading::kUndecided;
  } else if (-margin < effect.low && effect.high < margin) {
    c->reading = ComparisonReading::kEquivalent;
  } else if (effect.high < 0.0) {
    c->reading = ComparisonReading::kABetter;
  } else if (effect.low > 0.0) {
    c->reading = ComparisonReading::kBBetter;
  } else {
    c->reading = ComparisonReading::kUndecided;
  }
}

// Paired: d_s over the seeds in both maps.
void compare_paired(const SeedResults& a, const SeedResults& b, const ComparisonOptions& options,
                    Comparison* c) {
  std::vector<double> d;
  for (const auto& [seed, mse_a] : a) {
    const auto it = b.find(seed);
    if (it == b.end()) continue;
    const double la = log_mse(mse_a), lb = log_mse(it->second);
    c->diverged_a += std::isinf(la) ? 1 : 0;
    c->diverged_b += std::isinf(lb) ? 1 : 0;
    d.push_back(log_difference(la, lb));
  }
  c->n_pairs = c->n_a = c->n_b = static_cast<int>(d.size());
  if (d.empty()) {
    c->effect = c->effect_coverage = c->p_a_less = kNan;
    c->effect_interval = c->p_a_less_interval = Interval{kNan, kNan};
    return;
  }
  c->effect = quantile_linear(d, 0.5);
  if (options.effect_interval == EffectInterval::kPercentileBootstrap) {
    c->effect_interval = bootstrap_median_interval(d, options.bootstrap);
    c->effect_coverage = kNan;
  } else {
    c->effect_interval = order_statistic_median_interval(d, options.confidence);
    c->effect_coverage =
        median_rank_interval(static_cast<int>(d.size()), options.confidence).coverage;
  }
  double wins = 0.0;
  for (double x : d) wins += x < 0.0 ? 1.0 : (x == 0.0 ? 0.5 : 0.0);
  c->p_a_less = wins / static_cast<double>(d.size());
  c->p_a_less_interval = wilson_interval(wins, static_cast<int>(d.size()), options.confidence);
}

// Unpaired: every seed of each side.
void compare_unpaired(const SeedResults& a, const SeedResults& b, const ComparisonOptions& options,
                      Comparison* c) {
  std::vector<double> la, lb;
  for (const auto& entry : a) la.push_back(log_mse(entry.second));
  for (const auto& entry : b) lb.push_back(log_mse(entry.second));
  for (double x : la) c->diverged_a += std::isinf(x) ? 1 : 0;
  for (double y : lb) c->diverged_b += std::isinf(y) ? 1 : 0;
  c->n_a = static_cast<int>(la.size());
  c->n_b = static_cast<int>(lb.size());
  c->effect = hodges_lehmann_shift(la, lb);
  c->effect_interval = hodges_lehmann_interval(la, lb, options.confidence);
  c->effect_coverage = shift_rank_interval(c->n_a, c->n_b, options.confidence).coverage;
  double wins = 0.0;
  for (double x : la) {
    for (double y : lb) wins += x < y ? 1.0 : (x == y ? 0.5 : 0.0);
  }
  c->p_a_less = wins / (static_cast<double>(c->n_a) * c->n_b);
  c->p_a_less_interval = newcombe_interval(c->p_a_less, c->n_a, c->n_b, options.confidence);
}

std::string csv_number(double v) {
  if (std::isnan(v)) return "";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6e", v);
  return buf;
}

std::string csv_text(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return quoted + "\"";
}

}  // namespace

std::string render_comparisons_csv(const std::vector<NamedComparison>& comparisons, double delta,
                                   int list) {
  const std::string lead = list > 0 ? std::to_string(list) + "," : "";
  std::string out = std::string(list > 0 ? "list," : "") +
                    "a,b,paired,n_a,n_b,n_pairs,diverged_a,diverged_b,effect,effect_low,"
                    "effect_high,effect_coverage,p_a_less,p_low,p_high,delta,reading\n";
  for (const NamedComparison& named : comparisons) {
    const Comparison& c = named.comparison;
    out += lead + csv_text(named.a) + "," + csv_text(named.b) + "," + (c.paired ? "1" : "0");
    for (int count : {c.n_a, c.n_b, c.n_pairs, c.diverged_a, c.diverged_b}) {
      out += "," + std::to_string(count);
    }
    for (double v : {c.effect, c.effect_interval.low, c.effect_interval.high, c.effect_coverage,
                     c.p_a_less, c.p_a_less_interval.low, c.p_a_less_interval.high, delta}) {
      out += "," + csv_number(v);
    }
    out += "," + to_string(c.reading) + "\n";
  }
  return out;
}

void ComparisonOptions::validate() const {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("Invalid ComparisonOptions: " + what);
  };
  if (!(delta > 1.0)) fail("delta = " + std::to_string(delta) + "; violated constraint: delta > 1");
  if (!(confidence > 0.0 && confidence < 1.0)) {
    fail("confidence = " + std::to_string(confidence) +
         "; violated constraint: 0 < confidence < 1");
  }
  if (min_seeds < 1) {
    fail("min_seeds = " + std::to_string(min_seeds) + "; violated constraint: min_seeds >= 1");
  }
  bootstrap.validate();
}

Comparison compare_cells(const SeedResults& a, const SeedResults& b, bool paired,
                         const ComparisonOptions& options) {
  options.validate();
  if (a.empty() || b.empty()) throw std::invalid_argument("compare_cells: a side without seeds");
  Comparison c;
  c.paired = paired;
  if (paired) {
    compare_paired(a, b, options, &c);
  } else {
    compare_unpaired(a, b, options, &c);
  }
  const bool enough = std::min(c.n_a, c.n_b) >= options.min_seeds;
  read(c.effect_interval, std::log10(options.delta), enough, &c);
  return c;
}

bool cells_are_paired(const RunConfig& a, const RunConfig& b) {
  // b with everything that leaves initialization, data and batches alone
  // taken from a: equal cell keys then mean equal networks, data and batches.
  RunConfig b_as_a = b;
  b_as_a.integrator = a.integrator;
  b_as_a.regularizer = a.regularizer;
  b_as_a.training = a.training;
  b_as_a.training.batch_size = b.training.batch_size;
  return a.cell_key() == b_as_a.cell_key();
}

}  // namespace phnn
