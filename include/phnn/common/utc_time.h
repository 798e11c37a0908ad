// include/phnn/common/utc_time.h — the wall-clock time as ISO 8601 UTC text
// (provenance, run start/end times, the writer lock). Touches no file.
#pragma once

#include <ctime>
#include <string>

namespace phnn {

/// "2024-05-01T12:00:00Z": now, UTC, to the second.
inline std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buf;
}

}  // namespace phnn
