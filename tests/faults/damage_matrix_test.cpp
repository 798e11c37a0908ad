// tests/faults/damage_matrix_test.cpp — the damage matrix (ctest -L faults):
// in a small finished results file, one byte of every column class of /runs
// (every dataset of /runs, three of /runs/config), of the run's weights, of
// /data, of the sweep attributes and of the digests is flipped, and for 64-bit
// numbers also a high bit; `phnn verify` must name the damage, and `phnn
// sweep` on the file must either restore every stored byte (re-read, not
// judged by the exit status) or refuse naming it and leave the file as it
// was — never leave a file that verifies with the damage in it. Damage that
// leaves every value in range (a status turned pending or failed, two rows
// with one id) is also given to `phnn reduce` and `phnn merge`.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <utility>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/store/results_file.h"
#include "test_util.h"

namespace phnn {
namespace {

// sweeps/tiny.toml with checkpoints, so that every column exists.
const char* kSweep = R"(name = "damage-matrix-name"
[data]
num_validation = 50
num_inference = 5
[training]
steps = 20
eval_every = 10
checkpoints = [10, 20]
[grid]
systems = ["harmonic"]
models = ["phnn-jr-rk2", "node-rk2"]
sizes = ["small"]
n_train = [25]
seeds = [0, 1, 2]
)";
constexpr int kRows = 6;

// One damage: the byte at `at` of the file xor `mask`, or, when `bytes` is
// not empty, the bytes from `at` replaced by it; `verify` must print one of
// `named` (the dataset, attribute or row).
struct Case {
  std::string label;
  std::uint64_t at = 0;
  unsigned char mask = 0;
  std::vector<std::string> named;
  std::string bytes = {};
};

int run(const std::string& command, const std::string& log) {
  const int status = std::system(("timeout -k 5 120 " + command + " > " + log + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Every stored byte the checks cover, by name: the datasets of /runs, the
// weights and /data with their attributes, the file's sweep and digest
// attributes.
std::map<std::string, std::string> snapshot(const std::string& path) {
  const h5::File file = h5::File::open(path, h5::Access::kReadOnly);
  std::map<std::string, std::string> out;
  for (const char* name :
       {"sweep_name", "sweep_text", "sweep_hash", "checksum_version", "digest"}) {
    out[std::string("@") + name] = file.attribute_bytes("/", name);
  }
  std::vector<std::string> objects = file.objects_under("/runs");
  for (const std::string& o : file.objects_under("/data")) objects.push_back(o);
  objects.push_back("/weights");
  for (const std::string& object : objects) {
    if (file.is_dataset(object)) out[object] = file.read_row_bytes(object);
    for (const std::string& name : file.attribute_names(object)) {
      out[object + "@" + name] = file.attribute_bytes(object, name);
    }
  }
  return out;
}

class DamageMatrixTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "phnn_damage_" + std::to_string(::getpid());
    ASSERT_EQ(std::system(("rm -rf " + dir_ + " && mkdir -p " + dir_ + "/original").c_str()), 0);
    sweep_ = dir_ + "/matrix.toml";
    std::ofstream(sweep_) << kSweep;
    original_ = dir_ + "/original/r.h5";
    ASSERT_EQ(run(std::string(PHNN_BINARY) + " sweep " + sweep_ + " --quiet --out " + original_,
                  dir_ + "/original.log"),
              0)
        << testing_util::read_all(dir_ + "/original.log");
    bytes_ = testing_util::read_all(original_);
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  std::vector<Case> cases() const;
  std::vector<Case> status_and_id_cases(const h5::File& file) const;
  std::string damaged_copy(const Case& c, const std::string& here) const;
  std::string check_reduce_and_merge(const Case& c, int index) const;
  void add_column_cases(const h5::File& file, std::vector<Case>* cases) const;
  void add_text_case(const std::string& label, const std::string& text, std::size_t offset,
                     const std::string& named, std::vector<Case>* cases) const;
  std::string check(const Case& c, int index, bool* refused) const;

  std::string dir_, sweep_, original_, bytes_;
  mutable std::mutex h5_;
};

// Every dataset of /runs but most of /runs/config: one byte of row r (r
// turns with the column), and the high bit of a 64-bit element.
void DamageMatrixTest::add_column_cases(const h5::File& file, std::vector<Case>* cases) const {
  int turn = 0;
  for (const std::string& column : file.objects_under("/runs")) {
    if (!file.is_dataset(column)) continue;
    if (column.rfind("/runs/config/", 0) == 0 && column != "/runs/config/learning_rate" &&
        column != "/runs/config/model" && column != "/runs/config/seed") {
      continue;
    }
    const int row = turn++ % kRows;
    const std::uint64_t row_bytes = file.read_row_bytes(column, 0, 1).size();
    const std::uint64_t start = file.data_address(column) + row_bytes * row;
    bool is_text = false;
    try {
      file.read_ints(column, 0, 1);  // numbers convert, text does not
    } catch (const h5::Error&) {
      is_text = true;
    }
    const std::vector<std::string> named =
        column.rfind("/runs/config/", 0) == 0 || column == "/runs/id" ||
                column == "/runs/canonical" || column == "/runs/system" ||
                column == "/runs/model" || column == "/runs/integrator" || column == "/runs/size" ||
                column == "/runs/regularizer" || column == "/runs/n_train" ||
                column == "/runs/seed" || column == "/runs/n_x" || column == "/runs/studies" ||
                column == "/runs/weights_offset" || column == "/runs/weights_layout"
            ? std::vector<std::string>{"damaged: " + column + ":"}
            : std::vector<std::string>{"(row " + std::to_string(row) + ")",
                                       column + "[" + std::to_string(row) + "]"};
    // A middle element of an array row, the first of a scalar.
    const std::uint64_t element = is_text ? 0 : (row_bytes / 8 / 2) * 8;
    cases->push_back({column + " byte", start + element, 0xff, named});
    if (is_text) {
      cases->push_back({column + " padding", start + row_bytes - 1, 0x20, named});
    } else {
      cases->push_back({column + " high bit", start + element + 7, 0x40, named});
    }
  }
}

// A byte of `text` at `offset`, where the file holds it once but for copies
// inside other texts (a name in the sweep text, a hash in a digest line:
// preceded by '"' or ' ').
void DamageMatrixTest::add_text_case(const std::string& label, const std::string& text,
                                     std::size_t offset, const std::string& named,
                                     std::vector<Case>* cases) const {
  std::vector<std::size_t> found;
  for (std::size_t at = bytes_.find(text); at != std::string::npos;
       at = bytes_.find(text, at + 1)) {
    if (at == 0 || (bytes_[at - 1] != '"' && bytes_[at - 1] != ' ')) found.push_back(at);
  }
  ASSERT_EQ(found.size(), 1u) << label << ": not once in the file";
  cases->push_back({label, found[0] + offset, 0x01, {"damaged: " + named + ":"}});
}

// Damage that leaves every value in range (2026-11-28): a finished row's
// status turned pending (it would drop out of every check) or failed, and
// one row's id replaced by another row's (two rows with one id).
std::vector<Case> DamageMatrixTest::status_and_id_cases(const h5::File& file) const {
  std::vector<Case> cases;
  const std::uint64_t status = file.data_address("/runs/status");
  for (const auto& [row, to] : {std::pair<int, std::int64_t>{2, 0}, {5, 3}}) {
    const std::int64_t code = file.read_ints("/runs/status", static_cast<std::uint64_t>(row), 1).at(0);
    const std::string r = std::to_string(row);
    cases.push_back({"/runs/status[" + r + "] " + std::to_string(code) + " -> " + std::to_string(to),
                     status + 8 * static_cast<std::uint64_t>(row),
                     static_cast<unsigned char>(code ^ to), {"(row " + r + ")", "/runs/status[" + r + "]"}});
  }
  const std::uint64_t id_bytes = file.read_row_bytes("/runs/id", 0, 1).size();
  const std::string first = file.read_row_bytes("/runs/id", 0, 1);
  cases.push_back({"/runs/id[1] = /runs/id[0]", file.data_address("/runs/id") + id_bytes, 0,
                   {"repeats (row 1)", "damaged: /runs/id:"}, first});
  return cases;
}

std::vector<Case> DamageMatrixTest::cases() const {
  std::vector<Case> cases;
  const h5::File file = h5::File::open(original_, h5::Access::kReadOnly);
  add_column_cases(file, &cases);
  for (Case& c : status_and_id_cases(file)) cases.push_back(std::move(c));
  const std::int64_t offset = file.read_ints("/runs/weights_offset", 4, 1).at(0);
  const std::uint64_t weights = file.data_address("/weights") + 8 * (offset + 3);
  cases.push_back({"/weights byte", weights, 0xff, {"(row 4)"}});
  cases.push_back({"/weights high bit", weights + 7, 0x40, {"(row 4)"}});
  for (const char* name : {"train/x", "train/position", "validation/u", "inference/states"}) {
    const std::string dataset = std::string("/data/harmonic/") + name;
    const std::uint64_t at = file.data_address(dataset) + 8;
    cases.push_back({dataset + " byte", at, 0xff, {"damaged: " + dataset + ":"}});
    cases.push_back({dataset + " high bit", at + 7, 0x40, {"damaged: " + dataset + ":"}});
  }
  const std::string text = file.string_attribute("/", "sweep_text");
  add_text_case("@sweep_text", text, text.find("seeds = [0, 1, 2]") + 12, "@sweep_text", &cases);
  add_text_case("@sweep_hash", file.string_attribute("/", "sweep_hash"), 3, "@sweep_hash", &cases);
  add_text_case("@sweep_name", "damage-matrix-name", 2, "@sweep_name", &cases);
  // The file digest's and the data group's own lines.
  const std::string digest = file.string_attribute("/", "digest");
  const std::string seed_line = digest.substr(digest.find("/runs/seed "), 27);
  add_text_case("@digest", seed_line, 20, "/runs/seed", &cases);
  const std::string group = file.string_attribute("/data/harmonic", "digest");
  const std::string x_line = group.substr(group.find("/data/harmonic/train/x "), 40);
  add_text_case("/data/harmonic@digest", x_line, 30, "/data/harmonic/train/x", &cases);
  return cases;
}

// "" if case `c` passes: verify names the damage, and the resume restores
// every byte or refuses naming it and leaves the file alone.
// The damaged file at here/r.h5, with the original's journals; returns its
// bytes.
std::string DamageMatrixTest::damaged_copy(const Case& c, const std::string& here) const {
  std::system(("rm -rf " + here + " && mkdir -p " + here + " && cp -a " + original_ + " " +
               original_ + ".journal " + here + "/")
                  .c_str());
  std::string damaged = bytes_;
  if (c.bytes.empty()) {
    damaged[c.at] = static_cast<char>(damaged[c.at] ^ c.mask);
  } else {
    damaged.replace(c.at, c.bytes.size(), c.bytes);
  }
  std::ofstream(here + "/r.h5", std::ios::binary | std::ios::trunc) << damaged;
  return damaged;
}

std::string DamageMatrixTest::check(const Case& c, int index, bool* refused) const {
  const std::string here = dir_ + "/case" + std::to_string(index);
  const std::string path = here + "/r.h5";
  const std::string damaged = damaged_copy(c, here);
  auto names_it = [&](const std::string& log) {
    for (const std::string& n : c.named) {
      if (log.find(n) != std::string::npos) return true;
    }
    return false;
  };
  const std::string phnn = PHNN_BINARY;
  std::string log;
  if (run(phnn + " verify " + path, here + "/verify.log") != 1 ||
      !names_it(log = testing_util::read_all(here + "/verify.log"))) {
    return "verify did not report it (expected \"" + c.named.front() + "\"):\n" + log;
  }
  const int status = run(phnn + " sweep " + sweep_ + " --quiet --out " + path, here + "/sweep.log");
  log = testing_util::read_all(here + "/sweep.log");
  if (status != 0) {
    *refused = true;
    if (!names_it(log)) return "the resume refused without naming it:\n" + log;
    if (testing_util::read_all(path) != damaged) return "the refusing resume changed the file";
    return "";
  }
  const std::lock_guard<std::mutex> lock(h5_);  // HDF5 is not thread-safe
  const ResultsFile file = ResultsFile::open_read_only(path);
  if (!file.structure_problems().empty() || !file.file_damage().empty() ||
      !file.damaged_rows().empty()) {
    return "the resumed file does not verify:\n" + log;
  }
  const auto want = snapshot(original_), have = snapshot(path);
  for (const auto& [object, bytes] : want) {
    const auto it = have.find(object);
    if (it == have.end() || it->second != bytes) {
      return "the resume left " + object + " unlike the original (and the file verifies):\n" + log;
    }
  }
  if (have.size() != want.size()) return "the resumed file has other objects";
  return "";
}

// "" if `phnn reduce` names the damage (on stderr, the run left out) or
// refuses naming it, and `phnn merge` (the file as its one shard) refuses
// naming it and writes nothing.
std::string DamageMatrixTest::check_reduce_and_merge(const Case& c, int index) const {
  const std::string here = dir_ + "/other" + std::to_string(index);
  damaged_copy(c, here);
  const std::string phnn = PHNN_BINARY;
  auto names_it = [&](const std::string& log) {
    return std::any_of(c.named.begin(), c.named.end(),
                       [&](const std::string& n) { return log.find(n) != std::string::npos; }) ||
           log.find("damaged rows") != std::string::npos;
  };
  run(phnn + " reduce " + here + "/r.h5", here + "/reduce.log");
  std::string log = testing_util::read_all(here + "/reduce.log");
  if (!names_it(log)) return "reduce did not name it:\n" + log;
  const int status = run(phnn + " merge " + here + "/m.h5 " + here + "/r.h5", here + "/merge.log");
  log = testing_util::read_all(here + "/merge.log");
  if (status == 0) return "merge wrote a file from it:\n" + log;
  if (!names_it(log) && log.find("row ") == std::string::npos) {
    return "merge refused without naming it:\n" + log;
  }
  if (::access((here + "/m.h5").c_str(), F_OK) == 0) return "the refusing merge wrote m.h5";
  return "";
}

// Reduce and merge on the damage that leaves every value in range.
TEST_F(DamageMatrixTest, StatusAndIdDamageIsNamedByReduceAndRefusedByMerge) {
  std::vector<Case> all;
  {
    const h5::File file = h5::File::open(original_, h5::Access::kReadOnly);
    all = status_and_id_cases(file);
  }
  for (std::size_t k = 0; k < all.size(); ++k) {
    EXPECT_EQ(check_reduce_and_merge(all[k], static_cast<int>(k)), "") << all[k].label;
  }
}

TEST_F(DamageMatrixTest, EveryDamageIsNamedThenRepairedBitwiseOrRefused) {
  const std::vector<Case> all = cases();
  ASSERT_GE(all.size(), 80u);
  std::vector<std::string> failures(all.size());
  std::vector<char> refused(all.size(), 0);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t k = next++; k < all.size(); k = next++) {
      bool refusal = false;
      failures[k] = check(all[k], static_cast<int>(k), &refusal);
      refused[k] = refusal;
    }
  };
  std::thread second(worker);  // two at a time: each case is ~2 processes
  worker();
  second.join();
  const auto refusals = std::count(refused.begin(), refused.end(), 1);
  std::printf("%zu damages: %zu repaired bitwise, %zu refused by the resume\n", all.size(),
              all.size() - static_cast<std::size_t>(refusals), static_cast<std::size_t>(refusals));
  for (std::size_t k = 0; k < all.size(); ++k) {
    EXPECT_EQ(failures[k], "") << all[k].label << " (byte " << all[k].at << " ^ 0x" << std::hex
                               << int{all[k].mask} << std::dec << ")";
  }
}

}  // namespace
}  // namespace phnn
