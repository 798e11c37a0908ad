// tests/systems/system_file_test.cpp — system files: the shipped systems'
// derivatives, structure and discrete gradients against independent
// computations, and the errors of malformed files (FILE:LINE and the fix).
#include "phnn/systems/system_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <string>

#include "reference/oscillator.h"
#include "phnn/common/counted.h"
#include "phnn/systems/ph_system.h"
#include "systems/expression_code.h"
#include "systems/toy_system.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::string shipped(const std::string& name) {
  return std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name + ".toml";
}

const std::vector<std::string> kShipped = {"harmonic", "duffing",         "self-sustained",
                                           "pendulum", "coupled-duffing", "mass-chain"};

VecX random_state(std::mt19937_64* rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  VecX x(n);
  for (int i = 0; i < n; ++i) x(i) = u(*rng);
  return x;
}

TEST(SystemFileTest, ShippedSystemsHaveTheirDeclaredDimensions) {
  struct Dims {
    const char* name;
    int nx, nw, nu;
  };
  for (const Dims& d :
       {Dims{"harmonic", 2, 1, 1}, Dims{"pendulum", 2, 1, 1}, Dims{"pendulum-forced", 2, 1, 1},
        Dims{"coupled-duffing", 4, 2, 1}, Dims{"mass-chain", 6, 3, 1}}) {
    const auto sys = load_system_file(shipped(d.name));
    EXPECT_EQ(sys->n_x(), d.nx) << d.name;
    EXPECT_EQ(sys->n_w(), d.nw) << d.name;
    EXPECT_EQ(sys->n_u(), d.nu) << d.name;
    EXPECT_EQ(sys->name(), d.name);
  }
}

// gradH and the Hessian from GiNaC against central differences of H and
// gradH (h = 1e-5: truncation ~1e-10 H''', round-off ~1e-11 |H| / h).
TEST(SystemFileTest, DerivativesMatchCentralDifferences) {
  std::mt19937_64 rng(7);
  for (const std::string& name : kShipped) {
    const auto sys = load_system_file(shipped(name));
    const int n = sys->n_x();
    for (int trial = 0; trial < 5; ++trial) {
      const VecX x = random_state(&rng, n, 0.3);
      const VecX g = sys->grad_hamiltonian(x);
      const MatX hess = sys->hessian(x);
      const double eps = 1e-5;
      for (int i = 0; i < n; ++i) {
        VecX e = VecX::Zero(n);
        e(i) = eps;
        const double fd = (sys->hamiltonian(x + e) - sys->hamiltonian(x - e)) / (2 * eps);
        EXPECT_NEAR(g(i), fd, 1e-7 * (1 + std::abs(fd))) << name << " dH/dx" << i;
        const VecX fd_col =
            (sys->grad_hamiltonian(x + e) - sys->grad_hamiltonian(x - e)) / (2 * eps);
        for (int j = 0; j < n; ++j) {
          EXPECT_NEAR(hess(j, i), fd_col(j), 1e-6 * (1 + std::abs(fd_col(j)))) << name;
        }
      }
      if (sys->n_w() > 0) {
        const VecX w = random_state(&rng, sys->n_w(), 1.0);
        const MatX dz = sys->dissipation_jacobian(w);
        for (int l = 0; l < sys->n_w(); ++l) {
          VecX e = VecX::Zero(sys->n_w());
          e(l) = eps;
          const VecX fd = (sys->dissipation(w + e) - sys->dissipation(w - e)) / (2 * eps);
          for (int k = 0; k < sys->n_w(); ++k) EXPECT_NEAR(dz(k, l), fd(k), 1e-7) << name;
        }
      }
    }
  }
}

// The file versions of the paper's systems evaluate as the built-in ones.
TEST(SystemFileTest, PaperSystemsMatchTheBuiltInOscillators) {
  std::mt19937_64 rng(3);
  for (SystemKind kind : all_systems()) {
    const auto file = load_system_file(shipped(to_string(kind)));
    const auto builtin = make_system(to_string(kind));
    const Oscillator osc(OscillatorOptions::defaults(kind));
    EXPECT_EQ(file->S(), builtin->S()) << to_string(kind);
    EXPECT_EQ(file->J(), MatX(osc.J())) << to_string(kind) << ": J derived from S";
    EXPECT_EQ(file->rng_id(), builtin->rng_id());
    for (int trial = 0; trial < 10; ++trial) {
      const VecX x = random_state(&rng, 2, 0.5), dx = random_state(&rng, 2, 0.05);
      EXPECT_NEAR(file->hamiltonian(x), builtin->hamiltonian(x), 1e-14);
      EXPECT_LE((file->grad_hamiltonian(x) - builtin->grad_hamiltonian(x)).norm(), 1e-13);
      EXPECT_LE((file->discrete_gradient(x, dx) - builtin->discrete_gradient(x, dx)).norm(), 1e-12);
      const VecX w = random_state(&rng, 1, 2.0);
      EXPECT_NEAR(file->dissipation(w)(0), builtin->dissipation(w)(0), 1e-13);
    }
  }
  EXPECT_EQ(load_system_file(shipped("self-sustained"))->self_oscillation_interval(),
            Oscillator(OscillatorOptions::defaults(SystemKind::kSelfSustained))
                .self_oscillation_interval());
}

// DG property 1 (discrete chain rule) and property 2 (consistency).
TEST(SystemFileTest, DiscreteGradientSatisfiesTheChainRule) {
  std::mt19937_64 rng(11);
  for (const std::string& name : kShipped) {
    const auto sys = load_system_file(shipped(name));
    const int n = sys->n_x();
    for (int trial = 0; trial < 20; ++trial) {
      const VecX x = random_state(&rng, n, 0.4);
      const VecX dx = random_state(&rng, n, trial < 10 ? 0.1 : 1e-4);
      const double lhs = sys->discrete_gradient(x, dx).dot(dx);
      const double rhs = sys->hamiltonian(x + dx) - sys->hamiltonian(x);
      EXPECT_NEAR(lhs, rhs, 1e-14 * (1 + std::abs(sys->hamiltonian(x)))) << name;
    }
    const VecX x = random_state(&rng, n, 0.4);
    EXPECT_LE((sys->discrete_gradient(x, VecX::Zero(n)) - sys->grad_hamiltonian(x)).norm(), 1e-15);
  }
}

// d dg / d dx against central differences of dg (Newton's matrix).
TEST(SystemFileTest, DiscreteGradientJacobianMatchesDifferences) {
  std::mt19937_64 rng(5);
  for (const std::string& name : kShipped) {
    const auto sys = load_system_file(shipped(name));
    const int n = sys->n_x();
    const VecX x = random_state(&rng, n, 0.4), dx = random_state(&rng, n, 0.05);
    const MatX jac = sys->discrete_gradient_jacobian(x, dx);
    const double eps = 1e-6;
    for (int j = 0; j < n; ++j) {
      VecX e = VecX::Zero(n);
      e(j) = eps;
      const VecX fd =
          (sys->discrete_gradient(x, dx + e) - sys->discrete_gradient(x, dx - e)) / (2 * eps);
      EXPECT_LE((jac.col(j) - fd).norm(), 1e-6 * (1 + fd.norm())) << name << " column " << j;
    }
  }
}

// GiNaC's own order of a sum's terms depends on symbol serials and
// addresses; the muParser source must not: the same expression built from
// symbols made in either order prints the same text.
TEST(SystemFileTest, MuparserSourceDoesNotDependOnGinacsTermOrder) {
  std::string printed[2];
  for (int order = 0; order < 2; ++order) {
    std::vector<GiNaC::realsymbol> made;
    for (int k = 0; k < 3; ++k) made.emplace_back(std::string(1, (order == 0 ? "abc" : "cba")[k]));
    const GiNaC::ex a = made[order == 0 ? 0 : 2], b = made[1], c = made[order == 0 ? 2 : 0];
    const GiNaC::ex e = GiNaC::expand(GiNaC::pow(a + 2 * b - c / 3, 3) + GiNaC::sin(a * b) * c);
    printed[order] = internal::muparser_source(e);
  }
  EXPECT_EQ(printed[0], printed[1]);
  EXPECT_THAT(printed[0], HasSubstr("phnn_sin("));
}

TEST(SystemFileTest, PhasePairsComeFromThePlotsTableOrConsecutiveStates) {
  const auto chain = load_system_file(shipped("coupled-duffing"));
  const std::vector<std::array<int, 2>> expected = {{0, 1}, {2, 3}, {0, 2}};
  EXPECT_EQ(chain->phase_pairs(), expected);
  EXPECT_EQ(make_system("duffing")->phase_pairs(), (std::vector<std::array<int, 2>>{{0, 1}}));
}

// ---- malformed files: FILE:LINE and the fix ---------------------------------

using testing_util::toy_error_of;
using testing_util::toy_with;
const char* const kGood = testing_util::kToySystem;

std::string replaced(const std::string& from, const std::string& to) { return toy_with(from, to); }
std::string error_of(const std::string& text) { return toy_error_of(text); }

TEST(SystemFileErrorTest, TheGoodFileCompiles) { EXPECT_EQ(error_of(kGood), "(no error)"); }

TEST(SystemFileErrorTest, UnknownSymbolInTheEnergy) {
  EXPECT_THAT(error_of(replaced("k*q^2/2", "kk*q^2/2")),
              AllOf(HasSubstr("toy.toml:5:"), HasSubstr("unknown symbol \"kk\""),
                    HasSubstr("declare it under [parameters]")));
}

TEST(SystemFileErrorTest, StructureMatrixNotSkewSymmetric) {
  EXPECT_THAT(
      error_of(replaced("[-1, 0, -1, -1]", "[-1, 0, -1, 1]")),
      AllOf(HasSubstr("toy.toml:7:"), HasSubstr("not skew-symmetric"), HasSubstr("S[4][2]")));
}

TEST(SystemFileErrorTest, StructureMatrixOfTheWrongSize) {
  EXPECT_THAT(error_of(replaced(", [0, 1, 0, 0]]", "]")),
              AllOf(HasSubstr("toy.toml:7:"), HasSubstr("4 x 4 matrix"), HasSubstr("got 3 rows")));
}

// Vectors and matrices have a fixed capacity (kMaxDimension): a larger S is
// refused where it is read, before anything of that size is built.
TEST(SystemFileErrorTest, StructureLargerThanTheSupportedSize) {
  std::string ports = "\"w\"";
  for (int i = 2; i <= kMaxDimension; ++i) ports += ", \"w" + std::to_string(i) + "\"";
  EXPECT_THAT(
      error_of(replaced("ports = [\"w\"]", "ports = [" + ports + "]")),
      AllOf(HasSubstr("toy.toml:7:"), HasSubstr("make S 35 square"), HasSubstr("at most 32")));
}

// Structure only (measured data): no H, z, [initial], [control]. It
// compiles; whatever needs the energy says so at its name; the generating
// keys without H are refused at their line.
TEST(SystemFileErrorTest, StructureOnlyFilesDescribeButDoNotGenerate) {
  const auto sys = load_system_file(shipped("pendulum-structure"));
  EXPECT_FALSE(sys->has_energy());
  EXPECT_EQ(sys->n_x(), 2);
  EXPECT_EQ(sys->n_w(), 1);
  EXPECT_EQ(sys->n_u(), 1);
  try {
    sys->hamiltonian(VecX::Zero(2));
    ADD_FAILURE() << "no energy, yet hamiltonian() returned";
  } catch (const SystemFileError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("pendulum-structure.toml:7:"),
                                HasSubstr("defines no energy H"), HasSubstr("phnn import")));
  }
  std::string text = kGood;
  text.erase(text.find("H = "), text.find('\n', text.find("H = ")) - text.find("H = ") + 1);
  EXPECT_THAT(error_of(text), AllOf(HasSubstr("toy.toml:5:"), HasSubstr("\"z\" generates data"),
                                    HasSubstr("add H")));
  EXPECT_THAT(error_of(replaced("H = \"p^2/(2*m) + k*q^2/2\"", "H = \" \"")),
              HasSubstr("\"H\" is empty"));
}

// The message says why H >= 0 and the constant that fixes it: the
// smallest H of the box (-0.5 at x = 0) rounded up to two digits.
TEST(SystemFileErrorTest, EnergyNegativeAtASampledInitialState) {
  EXPECT_THAT(error_of(replaced("k*q^2/2\"", "k*q^2/2 - 0.5\"")),
              AllOf(HasSubstr("toy.toml:5:"), HasSubstr("is negative"),
                    HasSubstr("H must be >= 0 where states are drawn"),
                    HasSubstr("add a constant C >= 0.5 to H")));
  EXPECT_THAT(error_of(replaced("k*q^2/2\"", "k*q^2/2 - 0.123456\"")),
              HasSubstr("add a constant C >= 0.13 to H"));
}

// z without ports says to declare them.
TEST(SystemFileErrorTest, DissipationWithoutPortsNamesThem) {
  std::string text = kGood;
  text.erase(text.find("ports = "), text.find('\n', text.find("ports = ")) - text.find("ports = ") + 1);
  EXPECT_THAT(error_of(text), AllOf(HasSubstr("for 0 ports"), HasSubstr("ports = [\"w\"]")));
}

TEST(SystemFileErrorTest, EnergyNotFinite) {
  EXPECT_THAT(error_of(replaced("k*q^2/2\"", "k*q^2/2 + log(q^2)\"")),
              AllOf(HasSubstr("toy.toml:5:"), HasSubstr("not finite")));
}

TEST(SystemFileErrorTest, EmptyEnergyInterval) {
  EXPECT_THAT(error_of(replaced("energy = [0.1, 1.0]", "energy = [1.0, 0.1]")),
              AllOf(HasSubstr("toy.toml:14:"), HasSubstr("is empty"), HasSubstr("lo <= hi")));
}

TEST(SystemFileErrorTest, UnknownTopLevelKeyWithSuggestion) {
  EXPECT_THAT(error_of(replaced("ports = [\"w\"]", "port = [\"w\"]")),
              AllOf(HasSubstr("toy.toml:4:"), HasSubstr("did you mean \"ports\"")));
}

TEST(SystemFileErrorTest, NonZeroPortBlock) {
  const std::string two_ports = R"(name = "toy2"
states = ["q", "p"]
ports = ["w1", "w2"]
H = "p^2/2 + q^2/2"
z = ["w1", "w2"]
S = [[0, 1, 0, 0], [-1, 0, -1, 0], [0, 1, 0, 1], [0, 0, -1, 0]]
[initial]
method = "energy"
energy = [0.1, 1.0]
)";
  EXPECT_THAT(error_of(two_ports), AllOf(HasSubstr("toy.toml:6:"), HasSubstr("S_ww")));
}

TEST(SystemFileErrorTest, DissipationLawCountDiffersFromPorts) {
  EXPECT_THAT(error_of(replaced("z = [\"c*w\"]", "z = [\"c*w\", \"w\"]")),
              AllOf(HasSubstr("toy.toml:6:"), HasSubstr("2 expressions for 1 port;")));
}

TEST(SystemFileErrorTest, UnknownInitialMethod) {
  EXPECT_THAT(error_of(replaced("method = \"energy\"", "method = \"enrgy\"")),
              AllOf(HasSubstr("toy.toml:13:"), HasSubstr("did you mean \"energy\"")));
}

TEST(SystemFileErrorTest, TomlSyntaxError) {
  EXPECT_THAT(error_of(replaced("m = 1.0", "m = 1.0.0")),
              AllOf(HasSubstr("toy.toml:9:"), HasSubstr("not valid TOML")));
}

TEST(SystemFileErrorTest, ExpressionThatDoesNotParse) {
  EXPECT_THAT(error_of(replaced("z = [\"c*w\"]", "z = [\"c*(w\"]")),
              AllOf(HasSubstr("toy.toml:6:"), HasSubstr("is not an expression")));
}

TEST(SystemFileErrorTest, ReservedOrRepeatedNames) {
  EXPECT_THAT(error_of(replaced("states = [\"q\", \"p\"]", "states = [\"q\", \"exp\"]")),
              AllOf(HasSubstr("toy.toml:2:"), HasSubstr("reserved")));
  EXPECT_THAT(error_of(replaced("c = 0.1", "q = 0.1")),
              AllOf(HasSubstr("toy.toml:11:"), HasSubstr("used twice")));
}

TEST(SystemFileErrorTest, MissingFileNamesThePath) {
  EXPECT_THAT([] { load_system_file("/nonexistent/dir/x.toml"); },
              ::testing::ThrowsMessage<SystemFileError>(
                  AllOf(HasSubstr("/nonexistent/dir/x.toml"), HasSubstr("no such file"))));
}

TEST(SystemFileErrorTest, UnknownSystemNameSuggestsAFile) {
  EXPECT_THAT([] { make_system("double-pendulum"); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("or a system file")));
}

}  // namespace
}  // namespace phnn

namespace phnn {
namespace {

// Bare names of shipped system files resolve to sweeps/systems/NAME.toml
// (PHNN_SYSTEMS_DIR overrides where they are read from); the paper's three
// names stay the built-in systems; other bare names are not files.
TEST(ShippedSystemsTest, BareNamesResolveToShippedFiles) {
  const std::string dir = std::string(PHNN_SOURCE_DIR) + "/sweeps/systems";
  ASSERT_EQ(setenv("PHNN_SYSTEMS_DIR", dir.c_str(), 1), 0);
  EXPECT_EQ(shipped_systems_dir(), dir);
  EXPECT_EQ(shipped_system_path("coupled-duffing"), dir + "/coupled-duffing.toml");
  EXPECT_TRUE(is_system_file_argument("pendulum"));
  EXPECT_EQ(system_file_path("pendulum"), dir + "/pendulum.toml");
  EXPECT_EQ(make_system("coupled-duffing")->n_x(), 4);
  for (const std::string builtin : {"harmonic", "duffing", "self-sustained"}) {
    EXPECT_EQ(shipped_system_path(builtin), "") << builtin;  // a file of that name is shipped
    EXPECT_FALSE(is_system_file_argument(builtin)) << builtin;
  }
  for (const std::string other : {"nosuch", "../systems/pendulum", "pendulum.toml", ""}) {
    EXPECT_EQ(shipped_system_path(other), "") << other;
  }
  EXPECT_EQ(system_file_path("nosuch"), "nosuch");
  EXPECT_THROW(make_system("nosuch"), std::invalid_argument);
  ASSERT_EQ(setenv("PHNN_SYSTEMS_DIR", "/nonexistent-dir", 1), 0);
  EXPECT_EQ(shipped_system_path("pendulum"), "");  // the override is where they are read from
  ASSERT_EQ(unsetenv("PHNN_SYSTEMS_DIR"), 0);
  // Without the override: the binary's ../sweeps/systems (tests run from build/).
  EXPECT_NE(shipped_system_path("pendulum"), "");
}

}  // namespace
}  // namespace phnn

namespace phnn {
namespace {

TEST(CountedTest, OneIsSingular) {
  EXPECT_EQ(counted(1, "input"), "1 input");
  EXPECT_EQ(counted(0, "port"), "0 ports");
  EXPECT_EQ(counted(4, "state"), "4 states");
}

}  // namespace
}  // namespace phnn
