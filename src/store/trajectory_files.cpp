// src/store/trajectory_files.cpp — recorded trajectories from CSV and HDF5
// files, and the CSV writer (include/phnn/store/trajectory_files.h). Reads
// and writes only the files it is given.
#include "phnn/store/trajectory_files.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "h5/h5file.h"

namespace phnn {
namespace {

[[noreturn]] void fail(const std::string& message) { throw MeasuredDataError(message); }

std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

// Column k of the header: -2 trajectory, -1 t, 0 .. n_x-1 states, then inputs.
std::vector<int> header_roles(const std::vector<std::string>& header, const TrajectoryColumns& c,
                              const std::string& at) {
  std::vector<std::string> expected = {"trajectory", "t"};
  expected.insert(expected.end(), c.states.begin(), c.states.end());
  expected.insert(expected.end(), c.inputs.begin(), c.inputs.end());
  const std::string fix = "; the header must name trajectory, t, the states (" + list(c.states) +
                          ") and the inputs (" + (c.inputs.empty() ? "none" : list(c.inputs)) +
                          "), e.g. " + list(expected);
  std::vector<int> roles;
  std::set<std::string> seen;
  for (const std::string& name : header) {
    const auto it = std::find(expected.begin(), expected.end(), name);
    if (it == expected.end()) fail(at + ": unknown column \"" + name + "\"" + fix);
    if (!seen.insert(name).second) fail(at + ": column \"" + name + "\" appears twice" + fix);
    roles.push_back(static_cast<int>(it - expected.begin()) - 2);
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

double number(const std::string& field, const std::string& column, const std::string& at) {
  const char* b = field.data();
  const char* e = b + field.size();
  if (b != e && *b == '+') ++b;
  double v = 0;
  const auto r = std::from_chars(b, e, v);
  if (field.empty() || r.ec != std::errc() || r.ptr != e) {
    fail(at + ": column " + column + ": \"" + field + "\" is not a number; write a decimal number "
         "such as 0.25 or 1e-3");
  }
  if (!std::isfinite(v)) {
    fail(at + ": column " + column + " is " + field + "; phnn needs finite values: remove or "
         "repair the sample");
  }
  return v;
}

std::int64_t trajectory_id(const std::string& field, const std::string& at) {
  std::int64_t id = -1;
  const auto r = std::from_chars(field.data(), field.data() + field.size(), id);
  if (field.empty() || r.ec != std::errc() || r.ptr != field.data() + field.size() || id < 0) {
    fail(at + ": trajectory \"" + field + "\" is not a non-negative integer; number the "
         "trajectories 0, 1, 2, ...");
  }
  return id;
}

}  // namespace

std::vector<MeasuredTrajectory> read_trajectory_csv(const std::string& path,
                                                    const TrajectoryColumns& c) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path + ": cannot open it (" + std::strerror(errno) + "); check the path");
  const int nx = static_cast<int>(c.states.size()), nu = static_cast<int>(c.inputs.size());
  std::vector<MeasuredTrajectory> out;
  std::map<std::int64_t, int> first_line;  // trajectory id -> line of its first row
  std::vector<int> roles;
  std::vector<std::string> names;
  std::string line;
  for (int lineno = 1; std::getline(in, line); ++lineno) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (lineno == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // UTF-8 BOM
    if (trim(line).empty() || trim(line)[0] == '#') continue;
    const std::string at = path + ":" + std::to_string(lineno);
    const std::vector<std::string> fields = split_fields(line);
    if (roles.empty()) {
      roles = header_roles(fields, c, at);
      names = fields;
      continue;
    }
    if (fields.size() != roles.size()) {
      fail(at + ": " + std::to_string(fields.size()) + " fields where the header has " +
           std::to_string(roles.size()) + " (" + list(names) + "); give every row one value "
           "per column");
    }
    std::int64_t id = -1;
    double t = 0;
    VecX x(nx), u(nu);
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const int role = roles[k];
      if (role == -2) {
        id = trajectory_id(fields[k], at);
      } else {
        const double v = number(fields[k], names[k], at);
        if (role == -1) t = v;
        else if (role < nx) x(role) = v;
        else u(role - nx) = v;
      }
    }
    if (out.empty() || out.back().id != id) {
      const auto [it, fresh] = first_line.emplace(id, lineno);
      if (!fresh) {
        fail(at + ": trajectory " + std::to_string(id) + " continues here after other rows "
             "(it started at line " + std::to_string(it->second) + "); keep each trajectory's "
             "rows together, or give this one another id");
      }
      out.emplace_back();
      out.back().id = id;
      out.back().source = path;
    }
    MeasuredTrajectory& m = out.back();
    if (!m.t.empty() && !(t > m.t.back())) {
      std::ostringstream msg;
      msg.precision(17);
      msg << at << ": trajectory " << id << ": t = " << t << " does not increase (the previous "
          << "sample is at t = " << m.t.back() << "); sort each trajectory's rows by t";
      fail(msg.str());
    }
    m.t.push_back(t);
    m.x.push_back(x);
    m.u.push_back(u);
    m.line.push_back(lineno);
  }
  if (in.bad()) fail(path + ": read error (" + std::strerror(errno) + ")");
  if (roles.empty()) {
    fail(path + ": no header line (the file is empty); write the header trajectory,t," +
         list(c.states) + (c.inputs.empty() ? "" : "," + list(c.inputs)) + " and one row per sample");
  }
  if (out.empty()) fail(path + ": a header and no samples; add one row per sample");
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
    for (std::size_t k = 0; k < m.t.size(); ++k) {
      out << m.id;
      put(m.t[k]);
      for (Eigen::Index j = 0; j < m.x[k].size(); ++j) put(m.x[k](j));
      for (Eigen::Index j = 0; j < m.u[k].size(); ++j) put(m.u[k](j));
      out << '\n';
    }
  }
  out.flush();
  if (!out) fail(path + ": write failed (" + std::strerror(errno) + "); check the free space");
}

std::vector<MeasuredTrajectory> read_trajectory_h5(const std::string& path,
                                                   const TrajectoryColumns& c) {
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
  std::vector<MeasuredTrajectory> out;
  for (const std::string& name : file.link_names(root)) {
    const std::string g = root + "/" + name, at = path + ":" + g;
    MeasuredTrajectory m;
    m.id = trajectory_id(name, at);
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
    const std::vector<double> x = file.read_doubles(g + "/x");
    std::vector<double> u;
    if (nu > 0) {
      const auto du = file.dims(g + "/u");
      if (du.size() != 2 || du[0] != n || du[1] != nu) {
        fail(at + ": u must be (N x " + std::to_string(nu) + "), one column per input (" +
             list(c.inputs) + ")" + fix);
      }
      u = file.read_doubles(g + "/u");
    }
    for (std::size_t k = 0; k < n; ++k) {
      m.x.push_back(Eigen::Map<const VecX>(x.data() + k * nx, static_cast<Eigen::Index>(nx)));
      m.u.push_back(nu ? VecX(Eigen::Map<const VecX>(u.data() + k * nu, static_cast<Eigen::Index>(nu)))
                       : VecX(0));
    }
    out.push_back(std::move(m));
  }
  if (out.empty()) fail(path + ":" + root + " holds no trajectory" + fix);
  return out;
}

}  // namespace phnn
