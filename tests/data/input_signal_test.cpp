// tests/data/input_signal_test.cpp — time-varying inputs (control designs
// "sines", "chirp", "steps"): held over each sample, drawn from the counter
// RNG (a trajectory alone gives the same signal), the discrete power balance
// exact with u held over a step, pairs carrying u_n, the data-set file
// round trip, and the [control] table's errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "phnn/config/run_config.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/integrators/ph_steps.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// The shipped coupled oscillator (4 states, 2 ports, 1 input) with its
// [control] table replaced.
std::string coupled_with(const std::string& control) {
  std::ifstream in(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/coupled-duffing.toml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const auto begin = text.find("[control]");
  const auto end = text.find("\n[", begin + 1);
  return text.substr(0, begin) + control + "\n" + text.substr(end);
}

const char* kSines = "[control]\ndesign = \"sines\"\nfrequencies = [0.5, 1.3, 2.9]\n"
                     "amplitude = [0.2, 0.4]\nrange = [[-0.1, 0.1]]";
const char* kChirp = "[control]\ndesign = \"chirp\"\nfrequency = [0.2, 3.0]\namplitude = [0.5, 1.0]";
const char* kSteps = "[control]\ndesign = \"steps\"\nrange = [[-1, 1]]\nhold = 0.25";

DatasetOptions small_options() {
  DatasetOptions o;
  o.num_validation = 20;
  o.num_inference = 3;
  return o;
}

TEST(InputSignalTest, InputsAreHeldPerSampleAndReproducibleAlone) {
  const DatasetOptions o = small_options();
  const int samples = o.num_inference_steps() + 1;
  for (const char* control : {kSines, kChirp, kSteps}) {
    const auto system = compile_system(coupled_with(control), "forced.toml");
    const PhTrajectorySpec spec = ph_trajectory_spec(*system, o, 7);
    ASSERT_EQ(static_cast<int>(spec.inputs.size()), samples) << control;
    EXPECT_EQ(spec.u, spec.inputs[0]);
    int changes = 0;
    for (int k = 1; k < samples; ++k) changes += spec.inputs[k] != spec.inputs[k - 1];
    EXPECT_GT(changes, 0) << control;  // the input does vary
    // Counter-based: trajectory 7 alone, after others, gives the same signal.
    (void)ph_trajectory_spec(*system, o, 3);
    EXPECT_EQ(ph_trajectory_spec(*system, o, 7).inputs, spec.inputs) << control;
    EXPECT_NE(ph_trajectory_spec(*system, o, 8).inputs, spec.inputs) << control;
  }
}

// Each design's closed form at the sample times: sines within offset +
// amplitudes, steps constant over each hold with levels in range and
// 0.25 s = 25 samples at 100 Hz, chirp bounded by its amplitude.
TEST(InputSignalTest, SignalsFollowTheirDesigns) {
  const DatasetOptions o = small_options();
  const auto sines = compile_system(coupled_with(kSines), "forced.toml");
  const auto chirp = compile_system(coupled_with(kChirp), "forced.toml");
  const auto steps = compile_system(coupled_with(kSteps), "forced.toml");
  for (std::int64_t i = 0; i < 20; ++i) {
    for (const VecX& u : ph_trajectory_spec(*sines, o, i).inputs) EXPECT_LE(std::abs(u(0)), 0.1 + 3 * 0.4);
    for (const VecX& u : ph_trajectory_spec(*chirp, o, i).inputs) EXPECT_LE(std::abs(u(0)), 1.0);
    const auto s = ph_trajectory_spec(*steps, o, i).inputs;
    for (std::size_t k = 0; k < s.size(); ++k) {
      EXPECT_LE(std::abs(s[k](0)), 1.0);
      if (k % 25 != 0) {
        EXPECT_EQ(s[k], s[k - 1]) << "sample " << k;
      } else if (k > 0) {
        EXPECT_NE(s[k], s[k - 1]) << "sample " << k;
      }
    }
  }
}

// With u held over a step, the Gonzalez step keeps
//   H(x_{n+1}) - H(x_n) = -h (z^T w + u_n^T y)
// exactly (docs/METHOD.md "Time-varying inputs"), relative to the step's
// power scale, and the generator holds u of sample floor(n / stride).
TEST(InputSignalTest, DiscretePowerBalanceHoldsWithHeldInputs) {
  const DatasetOptions o;
  const int stride = o.stride();
  for (const char* control : {kSines, kChirp, kSteps}) {
    const auto system = compile_system(coupled_with(control), "forced.toml");
    const PhTrajectory traj = ph_generate_trajectory(*system, o, 2950, 2000);
    ASSERT_EQ(traj.inputs.size(), 2000u / stride + 1);
    const double h = o.generation_step;
    double worst = 0.0;
    for (std::size_t n = 0; n + 1 < traj.states.size(); ++n) {
      const VecX& u = traj.inputs[n / static_cast<std::size_t>(stride)];
      const PhImplicitStep step = ph_discrete_gradient_step(*system, traj.states[n], u, h, o.newton);
      ASSERT_EQ(step.status, StepStatus::kConverged);
      ASSERT_EQ(step.x_next, traj.states[n + 1]);  // the generator's own step and input
      const double h0 = system->hamiltonian(traj.states[n]), h1 = system->hamiltonian(step.x_next);
      const double zw = step.flows.z.dot(step.flows.w), uy = u.dot(step.flows.y);
      const double scale = std::abs(h0) + std::abs(h1) + h * std::abs(zw) + h * std::abs(uy);
      worst = std::max(worst, std::abs(h1 - h0 + h * (zw + uy)) / scale);
    }
    EXPECT_LE(worst, 1e-12) << control;
  }
}

TEST(InputSignalTest, PairsCarryTheirSamplesInputAndFilesKeepTheSignals) {
  const DatasetOptions o = small_options();
  const auto system = compile_system(coupled_with(kSines), "forced.toml");
  const PhSystemData data = make_ph_system_data(*system, o, 10);
  for (std::size_t i = 0; i < data.train.size(); ++i) {
    const PhTrajectorySpec spec = ph_trajectory_spec(*system, o, data.train.trajectory[i]);
    EXPECT_EQ(data.train.u[i], spec.inputs[static_cast<std::size_t>(data.train.position[i])]);
  }
  ASSERT_EQ(data.inference.inputs.size(), data.inference.size());
  EXPECT_EQ(data.inference.inputs[0].size(), data.inference.states[0].size());
  const std::string path =
      testing::TempDir() + std::to_string(::getpid()) + "_input_signal_roundtrip.h5";
  write_ph_dataset_file(path, data);
  const PhSystemData back = read_ph_dataset_file(path);
  EXPECT_EQ(back.inference.inputs, data.inference.inputs);
  EXPECT_EQ(data_set_checksum(back), data_set_checksum(data));
  // The signals are part of the checksum: a changed input is another data set.
  PhSystemData changed = data;
  changed.inference.inputs[1][5](0) += 1e-3;
  EXPECT_NE(data_set_checksum(changed), data_set_checksum(data));
  std::remove(path.c_str());
}

// data_set_checksum hashes its fields as they come (no string of a whole
// data set): the hash of the bytes joined, as it was computed before, so a
// data-set file's identity in sweeps is unchanged. The bytes: the system
// text and names (each with its length), then per split its step and every
// VecX (length, values), then the per-sample inputs.
TEST(InputSignalTest, TheChecksumIsTheHashOfEveryFieldJoined) {
  const auto system = compile_system(coupled_with(kSines), "forced.toml");
  const PhSystemData data = make_ph_system_data(*system, small_options(), 10);
  ASSERT_FALSE(data.inference.inputs.empty());
  std::string bytes;
  const auto raw = [&](const void* p, std::size_t n) { bytes.append(static_cast<const char*>(p), n); };
  const auto text = [&](const std::string& t) {
    const std::uint64_t n = t.size();
    raw(&n, sizeof n);
    bytes += t;
  };
  const auto vec = [&](const VecX& v) {
    const auto n = static_cast<std::uint64_t>(v.size());
    raw(&n, sizeof n);
    raw(v.data(), sizeof(double) * static_cast<std::size_t>(v.size()));
  };
  text(data.system_text);
  for (const auto& n : data.state_names) text(n);
  for (const auto& n : data.input_names) text(n);
  for (const PhPairSet* p : {&data.train, &data.validation}) {
    raw(&p->step, sizeof p->step);
    for (std::size_t i = 0; i < p->size(); ++i) vec(p->x[i]), vec(p->x_next[i]), vec(p->u[i]);
  }
  raw(&data.inference.step, sizeof data.inference.step);
  for (std::size_t i = 0; i < data.inference.size(); ++i) {
    vec(data.inference.u[i]);
    for (const VecX& x : data.inference.states[i]) vec(x);
  }
  for (const auto& traj : data.inference.inputs) {
    for (const VecX& u : traj) vec(u);
  }
  EXPECT_EQ(data_set_checksum(data), hex64(fnv1a64(bytes)));
}

std::string control_error(const std::string& control) {
  try {
    compile_system(coupled_with(control), "forced.toml");
  } catch (const SystemFileError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(InputSignalTest, ControlTableErrorsNameTheLineAndTheFix) {
  EXPECT_THAT(control_error("[control]\ndesign = \"sines\"\namplitude = [0.1, 0.2]"),
              AllOf(HasSubstr("forced.toml:"), HasSubstr("missing key \"frequencies\"")));
  EXPECT_THAT(control_error("[control]\ndesign = \"chirp\"\nfrequency = [1]\namplitude = [0, 1]"),
              HasSubstr("must be [f0, f1] in Hz"));
  EXPECT_THAT(control_error("[control]\ndesign = \"steps\"\nrange = [[-1, 1]]\nhold = 0"),
              HasSubstr("must be > 0"));
  EXPECT_THAT(control_error("[control]\ndesign = \"steps\"\nrange = [[-1, 1]]\nperiod = 1"),
              AllOf(HasSubstr("unknown key \"period\""), HasSubstr("it knows: design, range, hold")));
  EXPECT_THAT(control_error("[control]\ndesign = \"sine\""), HasSubstr("did you mean \"sines\"?"));
  // A hold shorter than a sample (here 1e-300 s: without the check, ~1e298
  // levels would be drawn per sample) is refused where the data are made.
  const auto tiny = compile_system(coupled_with("[control]\ndesign = \"steps\"\nrange = [[-1, 1]]\nhold = 1e-300"),
                                   "forced.toml");
  EXPECT_THAT([&] { ph_trajectory_spec(*tiny, small_options(), 0); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  AllOf(HasSubstr("forced.toml:"), HasSubstr("shorter than one sample"), HasSubstr("hold >= 0.01"))));
  // Found by a hostile campaign: frequencies above half the sample rate
  // (aliasing), numbers that overflow to a non-finite input, 65 sines.
  const auto fast = compile_system(coupled_with("[control]\ndesign = \"sines\"\nfrequencies = [1e6]\n"
                                                "amplitude = [0.1, 0.2]"), "forced.toml");
  EXPECT_THAT([&] { ph_trajectory_spec(*fast, small_options(), 0); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  AllOf(HasSubstr("above half the sample rate (50 Hz"), HasSubstr("<= 50 Hz"))));
  const auto huge = compile_system(coupled_with("[control]\ndesign = \"sines\"\nfrequencies = [1, 2]\n"
                                                "amplitude = [1e308, 1e308]"), "forced.toml");
  EXPECT_THAT([&] { ph_trajectory_spec(*huge, small_options(), 0); },
              ::testing::ThrowsMessage<std::invalid_argument>(AllOf(HasSubstr("not finite"), HasSubstr("overflow"))));
  std::string many = "1";
  for (int i = 0; i < 64; ++i) many += ", 1";
  EXPECT_THAT(control_error("[control]\ndesign = \"sines\"\nfrequencies = [" + many + "]\namplitude = [0, 1]"),
              HasSubstr("at most 64 sines"));
}

}  // namespace
}  // namespace phnn
