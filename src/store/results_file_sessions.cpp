// src/store/results_file_sessions.cpp — ResultsFile: who wrote the file
// (/provenance/session_<k>) and which sessions trained runs (by
// /runs/finished_utc; write_run stores it, read_run reads it).
#include "phnn/store/results_file.h"
#include "store/results_file_internal.h"

namespace phnn {

using namespace results_io;

namespace {

std::string value_of(const Provenance& session, const std::string& key) {
  for (const auto& [k, v] : session) {
    if (k == key) return v.substr(0, v.find('\0'));  // "finished" is NUL-padded until set
  }
  return "";
}

}  // namespace

// UTC stamps "YYYY-MM-DDTHH:MM:SSZ" order as strings.
std::vector<bool> sessions_with_runs(const std::vector<Provenance>& sessions,
                                     const std::vector<std::string>& finished_utc) {
  std::vector<bool> out(sessions.size(), finished_utc.empty());
  if (finished_utc.empty()) return out;  // no run times recorded: every session counts
  for (std::size_t k = 0; k < sessions.size(); ++k) {
    const std::string begin = value_of(sessions[k], "started");
    if (begin.empty()) {
      out[k] = true;
      continue;
    }
    std::string end = value_of(sessions[k], "finished");
    if (end.empty() && k + 1 < sessions.size()) end = value_of(sessions[k + 1], "started");
    for (const std::string& t : finished_utc) {
      if (!t.empty() && t >= begin && (end.empty() || t <= end)) {
        out[k] = true;
        break;
      }
    }
  }
  return out;
}

std::vector<bool> ResultsFile::sessions_with_runs() const {
  return phnn::sessions_with_runs(read_sessions(), impl_->has_run_times
                                                       ? impl_->strings(kFinishedUtc)
                                                       : std::vector<std::string>{});
}

// "finished" is reserved at the start with kFinishedWidth NUL bytes, so
// end_session overwrites the value in place: ending a session allocates
// nothing, and cannot fail for a full disk.
constexpr std::size_t kFinishedWidth = 20;  // "2026-11-25T08:43:21Z"

int ResultsFile::begin_session(const Provenance& provenance) {
  Impl& impl = *impl_;
  // Every rank reads the same metadata, so every rank picks the same k.
  int k = 0;
  impl.independent([&] {
    while (impl.file.exists(kProvenance + "/session_" + std::to_string(k))) ++k;
  });
  impl.session = kProvenance + "/session_" + std::to_string(k);
  impl.collective([&] {
    impl.file.create_group(impl.session);
    for (const auto& [key, value] : provenance) impl.file.set_attribute(impl.session, key, value);
    impl.file.set_attribute(impl.session, "finished", std::string(kFinishedWidth, '\0'));
    impl.file.flush();
  });
  return k;
}

void ResultsFile::end_session(const std::string& finished_utc) {
  if (impl_->session.empty()) return;
  end_session(std::stoi(impl_->session.substr(impl_->session.rfind('_') + 1)), finished_utc);
}

void ResultsFile::end_session(int session, const std::string& finished_utc) {
  Impl& impl = *impl_;
  const std::string group = kProvenance + "/session_" + std::to_string(session);
  std::string value = finished_utc;
  if (value.size() < kFinishedWidth) value.resize(kFinishedWidth, '\0');
  impl.collective([&] { impl.file.set_attribute(group, "finished", value); });
}

std::vector<Provenance> ResultsFile::read_sessions() const {
  const Impl& impl = *impl_;
  std::vector<Provenance> sessions;
  impl.independent([&] {
    for (int k = 0;; ++k) {
      const std::string group = kProvenance + "/session_" + std::to_string(k);
      if (!impl.file.exists(group)) break;
      Provenance p;
      for (const std::string& name : impl.file.attribute_names(group)) {
        std::string value = impl.file.string_attribute(group, name);
        if (name == "finished" && value.empty()) continue;  // reserved, not yet ended
        p.emplace_back(name, std::move(value));
      }
      sessions.push_back(std::move(p));
    }
  });
  return sessions;
}

}  // namespace phnn
