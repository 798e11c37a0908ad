// src/store/file_probe.cpp — see phnn/store/file_probe.h. Opens files
// read-only; writes nothing.
#include "phnn/store/file_probe.h"

#include "h5/h5file.h"

namespace phnn {

std::string hdf5_format_attribute(const std::string& path) {
  const h5::File file = h5::File::open(path, h5::Access::kReadOnly);
  return file.has_attribute("/", "format") ? file.string_attribute("/", "format")
                                           : std::string("(missing)");
}

bool is_hdf5_error(const std::exception& e) { return dynamic_cast<const h5::Error*>(&e) != nullptr; }

std::string hdf5_library_version() { return h5::library_version(); }

}  // namespace phnn
