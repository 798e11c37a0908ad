// src/store/trajectory_files.cpp — recorded trajectories from CSV and HDF5
// files, one at a time or all at once, and the CSV writer
// (include/phnn/store/trajectory_files.h). Reads and writes only the files
// it is given.
#include "phnn/store/trajectory_files.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string_view>

#include "h5/h5file.h"

namespace phnn {
namespace {

[[noreturn]] void fail(const std::string& message) { throw MeasuredDataError(message); }

std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// The fields of `line`, trimmed, into *out (views into `line`: no copies,
// so a row costs no allocation once *out has grown to the header's width).
void split_fields(std::string_view line, std::vector<std::string_view>* out) {
  out->clear();
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    out->push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos
                                                                           : comma - start)));
    if (comma == std::string_view::npos) return;
    start = comma + 1;
  }
}

// Column k of the header: -3 skipped, -2 trajectory, -1 t, 0 .. n_x-1
// states, then inputs.
std::vector<int> header_roles(const std::vector<std::string>& header, const TrajectoryColumns& c,
                              const std::string& at) {
  std::vector<std::string> expected = {"trajectory", "t"};
  expected.insert(expected.end(), c.states.begin(), c.states.end());
  expected.insert(expected.end(), c.inputs.begin(), c.inputs.end());
  const std::string fix = "; the header must name trajectory, t, the states (" + list(c.states) +
                          ") and the inputs (" + (c.inputs.empty() ? "none" : list(c.inputs)) +
                          "), e.g. " + list(expected) + " (skip other columns with `phnn import "
                          "--ignore-columns`; compute a state from others with [measurement] in "
                          "the system file)";
  std::vector<int> roles;
  std::set<std::string> seen;
  for (const std::string& name : header) {
    const auto it = std::find(expected.begin(), expected.end(), name);
    const bool skipped = it == expected.end() &&
                         std::find(c.ignore.begin(), c.ignore.end(), name) != c.ignore.end();
    if (it == expected.end() && !skipped) fail(at + ": unknown column \"" + name + "\"" + fix);
    if (!seen.insert(name).second) fail(at + ": column \"" + name + "\" appears twice" + fix);
    roles.push_back(skipped ? -3 : static_cast<int>(it - expected.begin()) - 2);
  }
  for (const std::string& name : expected) {
    if (!seen.count(name)) {
      const bool input = std::find(c.inputs.begin(), c.inputs.end(), name) != c.inputs.end();
      fail(at + ": missing column \"" + name + "\"" +
           (input ? " (the system has input " + name + "; record it for every sample)" : "") + fix);
    }
  }
  return roles;
}

// `at` is called only to word an error ("a.csv:14").
template <class Where>
double number(std::string_view field, const std::string& column, const Where& at) {
  const char* b = field.data();
  const char* e = b + field.size();
  if (b != e && *b == '+') ++b;
  double v = 0;
  const auto r = std::from_chars(b, e, v);
  if (field.empty() || r.ec != std::errc() || r.ptr != e) {
    fail(at() + ": column " + column + ": \"" + std::string(field) + "\" is not a number; write a "
         "decimal number such as 0.25 or 1e-3");
  }
  if (!std::isfinite(v)) {
    fail(at() + ": column " + column + " is " + std::string(field) + "; phnn needs finite values: "
         "remove or repair the sample");
  }
  return v;
}

template <class Where>
std::int64_t trajectory_id(std::string_view field, const Where& at) {
  std::int64_t id = -1;
  const auto r = std::from_chars(field.data(), field.data() + field.size(), id);
  if (field.empty() || r.ec != std::errc() || r.ptr != field.data() + field.size() || id < 0) {
    fail(at() + ": trajectory \"" + std::string(field) + "\" is not a non-negative integer; number "
         "the trajectories 0, 1, 2, ...");
  }
  return id;
}

// Trajectory id -> the line of its first row, for the ids of one file: ids
// that arrive in increasing order (the usual file) in a sorted array, 16
// bytes each, the others in a map (48 bytes each, as all were before).
class FirstLines {
 public:
  // The line `id` started at: `line` when it is new (and now recorded).
  int add(std::int64_t id, int line) {
    if (increasing_.empty() || id > increasing_.back().first) {
      increasing_.emplace_back(id, line);
      return line;
    }
    const auto it = std::lower_bound(increasing_.begin(), increasing_.end(), std::pair{id, 0},
                                     [](const auto& a, const auto& b) { return a.first < b.first; });
    if (it != increasing_.end() && it->first == id) return it->second;
    return others_.emplace(id, line).first->second;
  }

 private:
  std::vector<std::pair<std::int64_t, int>> increasing_;
  std::map<std::int64_t, int> others_;
};

// The rows of one CSV file into trajectories, one line at a time: fields
// are views into the line and samples go straight into the current
// trajectory's flat arrays, handed to `visit` once its last row is read and
// then cleared for the next (a file costs one trajectory, whatever its size).
class CsvTrajectories {
 public:
  // check_split: refuse a trajectory whose rows are split by another's
  // (FirstLines: 16 bytes a trajectory).
  CsvTrajectories(const std::string& path, const TrajectoryColumns& c, const TrajectoryVisitor& visit,
                  bool check_split)
      : path_(path), columns_(c), visit_(visit), check_split_(check_split),
        nx_(static_cast<int>(c.states.size())), nu_(static_cast<int>(c.inputs.size())),
        x_(c.states.size()), u_(c.inputs.size()), current_(nx_, nu_) {}

  void add_line(std::string_view text, int lineno);
  void finish();

 private:
  void add_sample(int lineno);
  void start_trajectory(std::int64_t id, int lineno);

  const std::string& path_;
  const TrajectoryColumns& columns_;
  const TrajectoryVisitor& visit_;
  const bool check_split_;
  const int nx_, nu_;
  std::vector<double> x_, u_;
  MeasuredTrajectory current_;  // no samples before the first row
  FirstLines first_line_;
  std::vector<int> roles_;
  std::vector<std::string> names_;
  std::vector<std::string_view> fields_;
};

void CsvTrajectories::add_line(std::string_view text, int lineno) {
  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  if (lineno == 1 && text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 BOM
  const std::string_view trimmed = trim(text);
  if (trimmed.empty() || trimmed[0] == '#') return;
  split_fields(text, &fields_);
  if (!roles_.empty()) return add_sample(lineno);
  names_.assign(fields_.begin(), fields_.end());
  roles_ = header_roles(names_, columns_, path_ + ":" + std::to_string(lineno));
}

void CsvTrajectories::add_sample(int lineno) {
  const auto at = [&] { return path_ + ":" + std::to_string(lineno); };
  if (fields_.size() != roles_.size()) {
    fail(at() + ": " + std::to_string(fields_.size()) + " fields where the header has " +
         std::to_string(roles_.size()) + " (" + list(names_) + "); give every row one value "
         "per column");
  }
  std::int64_t id = -1;
  double t = 0;
  for (std::size_t k = 0; k < fields_.size(); ++k) {
    const int role = roles_[k];
    if (role == -3) continue;
    if (role == -2) {
      id = trajectory_id(fields_[k], at);
      continue;
    }
    const double v = number(fields_[k], names_[k], at);
    if (role == -1) {
      t = v;
    } else if (role < nx_) {
      x_[static_cast<std::size_t>(role)] = v;
    } else {
      u_[static_cast<std::size_t>(role - nx_)] = v;
    }
  }
  if (current_.size() == 0 || current_.id != id) start_trajectory(id, lineno);
  MeasuredTrajectory& m = current_;
  if (m.size() > 0 && !(t > m.t.back())) {
    std::ostringstream msg;
    msg.precision(17);
    msg << at() << ": trajectory " << id << ": t = " << t << " does not increase (the previous "
        << "sample is at t = " << m.t.back() << "); sort each trajectory's rows by t";
    fail(msg.str());
  }
  m.add(t, x_.data(), u_.data());
  m.line.push_back(lineno);
}

// Hands the trajectory read so far to visit_ and starts trajectory `id`.
void CsvTrajectories::start_trajectory(std::int64_t id, int lineno) {
  const int started = check_split_ ? first_line_.add(id, lineno) : lineno;
  if (started != lineno) {
    fail(path_ + ":" + std::to_string(lineno) + ": trajectory " + std::to_string(id) +
         " continues here after other rows (it started at line " + std::to_string(started) +
         "); keep each trajectory's rows together, or give this one another id");
  }
  if (current_.size() > 0) visit_(current_);
  current_.t.clear();
  current_.x.clear();
  current_.u.clear();
  current_.line.clear();
  current_.id = id;
  current_.source = path_;
}

void CsvTrajectories::finish() {
  if (roles_.empty()) {
    fail(path_ + ": no header line (the file is empty); write the header trajectory,t," +
         list(columns_.states) + (columns_.inputs.empty() ? "" : "," + list(columns_.inputs)) +
         " and one row per sample");
  }
  if (current_.size() == 0) fail(path_ + ": a header and no samples; add one row per sample");
  visit_(current_);
}

void read_csv(const std::string& path, const TrajectoryColumns& c, const TrajectoryVisitor& visit,
              bool check_split) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path + ": cannot open it (" + std::strerror(errno) + "); check the path");
  CsvTrajectories reader(path, c, visit, check_split);
  std::string line;
  for (int lineno = 1; std::getline(in, line); ++lineno) reader.add_line(line, lineno);
  if (in.bad()) fail(path + ": read error (" + std::strerror(errno) + ")");
  reader.finish();
}

}  // namespace

void for_each_csv_trajectory(const std::string& path, const TrajectoryColumns& c,
                             const TrajectoryVisitor& visit) {
  read_csv(path, c, visit, /*check_split=*/true);
}

std::vector<MeasuredTrajectory> read_trajectory_csv(const std::string& path,
                                                    const TrajectoryColumns& c) {
  std::vector<MeasuredTrajectory> out;
  for_each_csv_trajectory(path, c, [&out](const MeasuredTrajectory& m) { out.push_back(m); });
  return out;
}

bool is_phnn_trajectory_csv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  return std::getline(in, line) && line.rfind(kTrajectoryCsvMarker, 0) == 0;
}

void write_trajectory_csv(const std::string& path, const TrajectoryColumns& c,
                          const std::vector<MeasuredTrajectory>& trajectories,
                          const std::string& note) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) fail(path + ": cannot create it (" + std::strerror(errno) + ")");
  out << kTrajectoryCsvMarker << (note.empty() ? "" : ": " + note) << "\n";
  out << "trajectory,t," << list(c.states) << (c.inputs.empty() ? "" : "," + list(c.inputs)) << "\n";
  char buf[64];
  const auto put = [&](double v) {
    const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest round trip
    out << ',';
    out.write(buf, r.ptr - buf);
  };
  for (const MeasuredTrajectory& m : trajectories) {
    const auto nx = static_cast<std::size_t>(m.n_x), nu = static_cast<std::size_t>(m.n_u);
    for (std::size_t k = 0; k < m.size(); ++k) {
      out << m.id;
      put(m.t[k]);
      for (std::size_t j = 0; j < nx; ++j) put(m.x[k * nx + j]);
      for (std::size_t j = 0; j < nu; ++j) put(m.u[k * nu + j]);
      out << '\n';
    }
  }
  out.flush();
  if (!out) fail(path + ": write failed (" + std::strerror(errno) + "); check the free space");
}

void for_each_h5_trajectory(const std::string& path, const TrajectoryColumns& c,
                            const TrajectoryVisitor& visit) {
  const std::string fix = "; see docs/DATASET_FORMAT.md, \"Trajectory files\"";
  if (!h5::File::is_hdf5(path)) fail(path + ": not an HDF5 file (missing or another format)" + fix);
  const h5::File file = h5::File::open(path, h5::Access::kReadOnly);
  const std::string root = "/trajectories";
  if (!file.exists(root)) fail(path + ": no group " + root + " (one group per trajectory)" + fix);
  for (const auto& [attr, names] : {std::pair<std::string, const std::vector<std::string>*>{"state_names", &c.states},
                                    {"input_names", &c.inputs}}) {
    if (file.has_attribute(root, attr) && file.string_attribute(root, attr) != list(*names)) {
      fail(path + ":" + root + ": attribute " + attr + " = \"" + file.string_attribute(root, attr) +
           "\" but the system's are \"" + list(*names) + "\"; write the columns in the system's "
           "order or choose the matching system file");
    }
  }
  const std::size_t nx = c.states.size(), nu = c.inputs.size();
  bool any = false;
  for (const std::string& name : file.link_names(root)) {
    const std::string g = root + "/" + name, at = path + ":" + g;
    MeasuredTrajectory m(static_cast<int>(c.states.size()), static_cast<int>(c.inputs.size()));
    m.id = trajectory_id(name, [&] { return at; });
    m.source = at;
    for (const char* d : {"t", "x"}) {
      if (!file.exists(g + "/" + d)) fail(at + ": no dataset " + d + fix);
    }
    if (nu > 0 && !file.exists(g + "/u")) {
      fail(at + ": no dataset u; the system has inputs (" + list(c.inputs) + "): record them" + fix);
    }
    const auto dt = file.dims(g + "/t"), dx = file.dims(g + "/x");
    const std::uint64_t n = dt.size() == 1 ? dt[0] : 0;
    if (dt.size() != 1 || dx.size() != 2 || dx[0] != n || dx[1] != nx) {
      fail(at + ": t must be (N) and x (N x " + std::to_string(nx) + "): one row per sample, one "
           "column per state (" + list(c.states) + ")" + fix);
    }
    m.t = file.read_doubles(g + "/t");
    m.x = file.read_doubles(g + "/x");  // row-major (N x n_x): the flat layout
    if (nu > 0) {
      const auto du = file.dims(g + "/u");
      if (du.size() != 2 || du[0] != n || du[1] != nu) {
        fail(at + ": u must be (N x " + std::to_string(nu) + "), one column per input (" +
             list(c.inputs) + ")" + fix);
      }
      m.u = file.read_doubles(g + "/u");
    }
    visit(m);
    any = true;
  }
  if (!any) fail(path + ":" + root + " holds no trajectory" + fix);
}

std::vector<MeasuredTrajectory> read_trajectory_h5(const std::string& path,
                                                   const TrajectoryColumns& c) {
  std::vector<MeasuredTrajectory> out;
  for_each_h5_trajectory(path, c, [&out](const MeasuredTrajectory& m) { out.push_back(m); });
  return out;
}

// A file read whole once is not checked again for split trajectories (a
// check of 16 bytes a trajectory): split_measured_stream checks every later
// pass against the first, trajectory by trajectory, so a file changed in
// between is refused all the same.
TrajectorySource recorded_trajectories(const std::vector<std::string>& files,
                                       const TrajectoryColumns& columns, const MeasurementMap& map) {
  auto read_whole = std::make_shared<std::vector<bool>>(files.size(), false);
  return [files, columns, &map, read_whole](const TrajectoryVisitor& visit) {
    std::string measurement_error;  // the first; thrown once every file is read
    MeasuredTrajectory states;
    const TrajectoryVisitor each = [&](const MeasuredTrajectory& m) {
      if (map.identity()) return visit(m);
      if (!measurement_error.empty()) return;
      try {
        apply_measurement(map, m, &states);
      } catch (const MeasuredDataError& e) {
        measurement_error = e.what();
        return;
      }
      visit(states);
    };
    for (std::size_t f = 0; f < files.size(); ++f) {
      if (h5::File::is_hdf5(files[f])) {
        for_each_h5_trajectory(files[f], columns, each);
      } else {
        read_csv(files[f], columns, each, /*check_split=*/!(*read_whole)[f]);
      }
      (*read_whole)[f] = true;
    }
    if (!measurement_error.empty()) fail(measurement_error);
  };
}

}  // namespace phnn
