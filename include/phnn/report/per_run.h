// include/phnn/report/per_run.h — one CSV row per run ("tidy" data for
// pandas and R): every configuration key of the run, its status and its
// per-run results. Pure functions: no HDF5, no MPI.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "phnn/config/result_columns.h"
#include "phnn/config/setting_columns.h"  // parse_canonical

namespace phnn {

/// One row of the results file, as the per-run export needs it (the scalar
/// columns of /runs; the arrays stay in the file).
struct RunRecord {
  /// /runs/id, /runs/studies ("I,II,III") and the table row label
  /// ("PHNN-S-DG").
  std::string id, studies, model_label;
  /// /runs/canonical: "key=value;..." with every field that determines the
  /// run (RunConfig::canonical()), the seed last.
  std::string canonical;
  /// Status, message and the scalar result columns (config/
  /// result_columns.h); its arrays stay empty.
  RunResult result;
  /// From /runs/trace (the validation points, step 0 first): how many there
  /// are, the validation loss at step 0 (how far training got: compare with
  /// best_validation_loss), and train loss, validation loss, kappa,
  /// sigma_max, rho at the last point; NaN for a run without a trace.
  std::int64_t trace_points = 0;
  /// /runs/checkpoint_*: per step budget, the inference MSE of the best
  /// weights up to it and the training seconds to reach it (empty when the
  /// sweep set no checkpoints). Rendered as mse_at_<step>, train_s_at_<step>.
  std::vector<std::int64_t> checkpoint_steps;
  std::vector<double> checkpoint_mse, checkpoint_train_seconds;
  double initial_validation_loss = 0.0;
  double final_train_loss = 0.0, final_validation_loss = 0.0;
  double final_kappa = 0.0, final_sigma_max = 0.0, final_rho = 0.0;
};

/// A tidy CSV, one line per record (in order) after a header:
///
///   run_id,studies,model_label,<config keys>,status,<result columns>,
///   trace_points,initial_validation_loss,final_train_loss,
///   final_validation_loss,final_kappa,final_sigma_max,final_rho,
///   [mse_at_<step>,train_s_at_<step>]...,message
///
/// <result columns> are those of config/result_columns.h in its order, by
/// their CSV names (mse, best_step, best_validation_loss, wall_time_s,
/// steps_taken, parameter_count, diverged_rollouts, newton_failures,
/// train_seconds).
/// <config keys> are the canonical keys of all records in order of first
/// appearance (system, model, integrator, size, n_train, regularizer, the
/// physics, data and training keys, ..., seed), so any axis a sweep varies has
/// its column; a key a run does not have (e.g. cubic_stiffness of a harmonic
/// run) is empty. Short canonical keys are renamed to their sweep-file names
/// (lr -> learning_rate, tau -> dg_min_dx_norm, ...) and the ones holding
/// several numbers are split, one column each (e0 -> energy_min, energy_max;
/// splits -> num_train_max, num_validation, num_inference; adam; newton; eeq;
/// z -> z1, z2, z3); unknown keys (and a rename that would repeat a name)
/// keep their name and value. Configuration values are copied as stored
/// (numbers with 17 significant digits). Doubles print "%.17g" (round-trip
/// exact), +inf as "inf", -inf as "-inf", NaN as "nan" (a pending or failed
/// run's numbers): pandas.read_csv reads them as float64. Fields are quoted
/// as RFC 4180 says (a field holding a comma, a double quote, CR or LF is
/// enclosed in double quotes, its quotes doubled); lines end in "\n".
std::string render_per_run_csv(const std::vector<RunRecord>& records);

}  // namespace phnn
