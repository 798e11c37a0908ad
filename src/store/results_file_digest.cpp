// src/store/results_file_digest.cpp — the digests of checksum rule 2
// (docs/RESULTS_FORMAT.md, "Checksums"): the file digest (sweep attributes,
// configuration columns) and one per /data group, the check that names each
// damaged object (file_damage), and their repairs: configuration rewritten
// from the sweep's runs, a /data group stored again.
#include <map>
#include <set>

#include "phnn/config/run_config.h"  // fnv1a64, hex64
#include "store/results_file_internal.h"

namespace phnn {
namespace results_io {
namespace {

constexpr const char* kSweepAttributes[] = {"sweep_name", "sweep_text", "sweep_hash"};

// An object's attributes, by name, each as name NUL bytes NUL; the digest
// attributes themselves and `complete` (set after the digest) left out.
std::string attribute_text(const h5::File& file, const std::string& object) {
  std::string text;
  for (const std::string& name : file.attribute_names(object)) {
    if (name == kDigestAttribute || name == "complete") continue;
    text += name + '\0' + file.attribute_bytes(object, name) + '\0';
  }
  return text;
}

std::string line(const std::string& object, const std::string& bytes) {
  return object + " " + hex64(fnv1a64(bytes)) + "\n";
}

// Digest lines as object -> hash text.
std::map<std::string, std::string> parse_digest(const std::string& digest) {
  std::map<std::string, std::string> out;
  std::size_t begin = 0;
  while (begin < digest.size()) {
    std::size_t end = digest.find('\n', begin);
    if (end == std::string::npos) end = digest.size();
    const std::string text = digest.substr(begin, end - begin);
    const std::size_t space = text.rfind(' ');
    if (space != std::string::npos) out[text.substr(0, space)] = text.substr(space + 1);
    begin = end + 1;
  }
  return out;
}

}  // namespace

std::string file_digest(const h5::File& file) {
  std::string digest;
  for (const char* name : kSweepAttributes) {
    digest += line(std::string("@") + name, file.attribute_bytes("/", name));
  }
  for (const std::string& column : configuration_columns(file)) {
    digest += line(column, file.read_row_bytes(column));
  }
  return digest;
}

std::string group_digest(const h5::File& file, const std::string& group) {
  std::string digest = line(group, attribute_text(file, group));
  for (const std::string& object : file.objects_under(group)) {
    const std::string data = file.is_dataset(object) ? file.read_row_bytes(object) : "";
    digest += line(object, data + '\0' + attribute_text(file, object));
  }
  return digest;
}

}  // namespace results_io

using namespace results_io;

namespace {

// Every object whose line differs between the recorded and the stored digest.
void compare_digests(const std::string& recorded, const std::string& stored,
                     std::vector<ResultsFile::Damage>* out) {
  const auto want = parse_digest(recorded), have = parse_digest(stored);
  std::set<std::string> objects;
  for (const auto& entry : want) objects.insert(entry.first);
  for (const auto& entry : have) objects.insert(entry.first);
  for (const std::string& object : objects) {
    const auto w = want.find(object), h = have.find(object);
    if (w == want.end()) {
      out->push_back({object, "not in the digest recorded with the file"});
    } else if (h == have.end()) {
      out->push_back({object, "missing, though the file's digest records it"});
    } else if (w->second != h->second) {
      out->push_back({object, "its bytes differ from the digest recorded with them"});
    }
  }
}

// "/" (the file digest) or a /data group: the digest recorded on it ("" if
// none) and the one its bytes give now.
std::pair<std::string, std::string> digests_of(const h5::File& file, const std::string& object) {
  const std::string recorded = file.has_attribute(object, kDigestAttribute)
                                   ? file.string_attribute(object, kDigestAttribute)
                                   : std::string();
  return {recorded, object == "/" ? file_digest(file) : group_digest(file, object)};
}

}  // namespace

std::vector<ResultsFile::Damage> ResultsFile::file_damage() const {
  std::vector<Damage> damage;
  if (impl_->checksum_version != 2) return damage;
  impl_->independent([&] {
    const h5::File& file = impl_->file;
    const std::int64_t version = file.int_attribute("/", kChecksumVersionAttribute);
    if (version != kChecksumVersion) {
      damage.push_back({"@" + kChecksumVersionAttribute,
                        "= " + std::to_string(version) + "; only " +
                            std::to_string(kChecksumVersion) + " is ever written"});
    }
    std::vector<std::string> objects = {"/"};
    if (file.exists("/data")) {
      for (const std::string& name : file.link_names("/data")) {
        if (file.has_attribute("/data/" + name, "complete")) objects.push_back("/data/" + name);
      }
    }
    for (const std::string& object : objects) {
      const auto [recorded, stored] = digests_of(file, object);
      if (recorded.empty()) {
        damage.push_back({object == "/" ? "@" + kDigestAttribute : object,
                          "no digest recorded (rule 2 records one)"});
      } else {
        compare_digests(recorded, stored, &damage);
      }
    }
    return 0;
  });
  return damage;
}

std::vector<std::string> ResultsFile::repair_configuration(
    const std::vector<RunConfig>& runs, const std::vector<std::string>& run_studies,
    const std::string& sweep_name, const std::string& sweep_text, const std::string& sweep_hash) {
  Impl& impl = *impl_;
  if (impl.checksum_version != 2) return {};
  const auto [recorded, before] = impl.independent([&] { return digests_of(impl.file, "/"); });
  std::vector<Damage> damaged;
  compare_digests(recorded, before, &damaged);
  const bool version_damaged =
      impl.independent([&] { return impl.file.int_attribute("/", kChecksumVersionAttribute); }) !=
      kChecksumVersion;
  if (damaged.empty() && !recorded.empty() && !version_damaged) return {};
  rewrite_configuration(runs, run_studies, sweep_name, sweep_text, sweep_hash);
  const std::string after = impl.independent([&] { return file_digest(impl.file); });
  std::vector<Damage> left;
  compare_digests(recorded, after, &left);
  // Rewriting changed no byte: the recorded digest itself was damaged.
  const bool digest_damaged = !left.empty() && after == before;
  if (!left.empty() && !digest_damaged) {
    std::string names;
    for (const Damage& d : left) names += (names.empty() ? "" : ", ") + d.object;
    throw std::runtime_error(path() + ": " + names + ": damaged, and rewriting from the sweep "
                             "file does not give the bytes recorded in the file's digest");
  }
  impl.independent([&] {
    impl.file.set_attribute("/", kChecksumVersionAttribute, kChecksumVersion);
    if (digest_damaged || recorded.empty()) impl.file.set_attribute("/", kDigestAttribute, after);
    return 0;
  });
  std::vector<std::string> repaired;
  for (const Damage& d : damaged) repaired.push_back(d.object);
  if (digest_damaged || recorded.empty()) repaired.push_back("@" + kDigestAttribute);
  if (version_damaged) repaired.push_back("@" + kChecksumVersionAttribute);
  return repaired;
}

std::vector<std::string> ResultsFile::repair_system_data(const std::string& system_name,
                                                         const std::function<void()>& store) {
  Impl& impl = *impl_;
  const std::string group = "/data/" + system_name;
  if (impl.checksum_version != 2 || !has_system_data(system_name)) return {};
  const auto [recorded, before] = impl.independent([&] { return digests_of(impl.file, group); });
  std::vector<Damage> damaged;
  compare_digests(recorded, before, &damaged);
  if (!recorded.empty() && damaged.empty()) return {};
  impl.independent([&] {
    impl.file.remove(group);
    return 0;
  });
  store();  // stores the group afresh, with its digest
  const std::string after = impl.independent([&] { return group_digest(impl.file, group); });
  if (after != recorded && after != before) {
    throw std::runtime_error(path() + ": " + group + " is damaged, and the data this program "
                             "generates for " + system_name + " differ from the digest recorded "
                             "with them");
  }
  std::vector<std::string> repaired;
  for (const Damage& d : damaged) repaired.push_back(d.object);
  if (recorded.empty()) repaired.push_back(group + "@" + kDigestAttribute);
  return repaired;
}

}  // namespace phnn
