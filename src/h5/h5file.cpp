// src/h5/h5file.cpp — h5::File: create/open/close (serial or MPI-IO),
// groups and attributes. Datasets and row I/O: h5file_datasets.cpp.
#include "h5/h5file.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <numeric>
#include <sstream>

#include "h5/h5_handle.h"

namespace phnn {
namespace h5 {
namespace {

using namespace detail;

// Silences HDF5's own error stack printing: we report errors ourselves.
const SilenceHdf5 kSilence;

}  // namespace

using namespace detail;

File::File(std::int64_t id, std::string path, MPI_Comm comm)
    : id_(id), path_(std::move(path)), comm_(comm) {}

File File::create(const std::string& path, MPI_Comm comm) {
  Handle fapl(file_access_plist(comm), H5Pclose);
  const hid_t id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get());
  if (id < 0) fail(path, "cannot create the HDF5 file", "is the directory writable?");
  return File(id, path, comm);
}

bool File::is_hdf5(const std::string& path) {
  std::ifstream probe(path);
  if (!probe.good()) return false;
  return H5Fis_hdf5(path.c_str()) > 0;
}

File File::open(const std::string& path, Access access, MPI_Comm comm) {
  std::ifstream probe(path);
  if (!probe.good()) fail(path, "no such file");
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    fail(path, "not an HDF5 file");
  }
  Handle fapl(file_access_plist(comm), H5Pclose);
  const unsigned flags = access == Access::kReadOnly ? H5F_ACC_RDONLY : H5F_ACC_RDWR;
  const hid_t id = H5Fopen(path.c_str(), flags, fapl.get());
  if (id < 0) {
    fail(path, "cannot open the HDF5 file",
         "truncated or damaged, or locked by another process (HDF5 file locking)");
  }
  return File(id, path, comm);
}

File::File(File&& other) noexcept
    : id_(other.id_), path_(std::move(other.path_)), comm_(other.comm_) {
  other.id_ = -1;
}

File& File::operator=(File&& other) noexcept {
  if (this != &other) {
    close();
    id_ = other.id_;
    path_ = std::move(other.path_);
    comm_ = other.comm_;
    other.id_ = -1;
  }
  return *this;
}

File::~File() {
  try {
    close();
  } catch (...) {
  }
}

void File::close() {
  if (id_ < 0) return;
  const hid_t id = id_;
  id_ = -1;
  if (H5Fclose(id) < 0) {
    fail(path_, "cannot close the HDF5 file: its last changes could not be written (disk "
                "full, file-size limit or I/O error?)");
  }
}

void File::flush() {
  if (id_ >= 0 && H5Fflush(id_, H5F_SCOPE_GLOBAL) < 0) fail(path_, "H5Fflush failed");
}

bool File::exists(const std::string& object) const {
  if (object == "/") return true;
  // Check every prefix: H5Lexists fails on a missing intermediate group.
  std::size_t pos = 0;
  while (true) {
    pos = object.find('/', pos + 1);
    const std::string prefix = object.substr(0, pos);
    if (!prefix.empty() && prefix != "/" &&
        H5Lexists(id_, prefix.c_str(), H5P_DEFAULT) <= 0) {
      return false;
    }
    if (pos == std::string::npos) return true;
  }
}

void File::create_group(const std::string& group) {
  std::size_t pos = 0;
  while (true) {
    pos = group.find('/', pos + 1);
    const std::string prefix = group.substr(0, pos);
    if (!prefix.empty() && prefix != "/" &&
        H5Lexists(id_, prefix.c_str(), H5P_DEFAULT) <= 0) {
      Handle g(H5Gcreate2(id_, prefix.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
               H5Gclose);
      if (!g.ok()) fail(path_, "cannot create group " + prefix);
    }
    if (pos == std::string::npos) return;
  }
}

void File::remove(const std::string& object) {
  if (!exists(object)) return;
  if (H5Ldelete(id_, object.c_str(), H5P_DEFAULT) < 0) fail(path_, "cannot remove " + object);
}

std::vector<std::string> File::attribute_names(const std::string& object) const {
  std::vector<std::string> names;
  Handle obj(open_object(id_, object), H5Oclose);
  if (!obj.ok()) fail(path_, "no object " + object);
  auto collect = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->push_back(name);
    return 0;
  };
  hsize_t index = 0;
  if (H5Aiterate2(obj.get(), H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names) < 0) {
    fail(path_, "cannot list the attributes of " + object);
  }
  return names;
}

std::vector<std::string> File::link_names(const std::string& group) const {
  std::vector<std::string> names;
  Handle g(H5Gopen2(id_, group.c_str(), H5P_DEFAULT), H5Gclose);
  if (!g.ok()) fail(path_, "no group " + group);
  auto collect = [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->push_back(name);
    return 0;
  };
  hsize_t index = 0;
  if (H5Literate(g.get(), H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names) < 0) {
    fail(path_, "cannot list the links of " + group);
  }
  return names;
}

std::vector<std::string> File::objects_under(const std::string& group) const {
  std::vector<std::string> out;
  const std::string base = group == "/" ? "" : group;
  for (const std::string& name : link_names(group)) {
    const std::string path = base + "/" + name;
    out.push_back(path);
    if (!is_dataset(path)) {
      const std::vector<std::string> below = objects_under(path);
      out.insert(out.end(), below.begin(), below.end());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool File::is_dataset(const std::string& object) const {
  if (!exists(object)) return false;
  Handle obj(open_object(id_, object), H5Oclose);
  return obj.ok() && H5Iget_type(obj.get()) == H5I_DATASET;
}

std::string library_version() {
  unsigned major = 0, minor = 0, release = 0;
  H5get_libversion(&major, &minor, &release);
  return "HDF5 " + std::to_string(major) + "." + std::to_string(minor) + "." +
         std::to_string(release);
}

namespace {
void write_attribute(hid_t file, const std::string& fname, const std::string& object,
                     const std::string& name, hid_t type, const void* value) {
  Handle obj(open_object(file, object), H5Oclose);
  if (!obj.ok()) fail(fname, "no object " + object + " for attribute " + name);
  if (H5Aexists(obj.get(), name.c_str()) > 0) {
    // The same type and size: overwrite the value in place (no allocation).
    Handle old(H5Aopen(obj.get(), name.c_str(), H5P_DEFAULT), H5Aclose);
    Handle old_type(H5Aget_type(old.get()), H5Tclose);
    // A fixed-length string of the same size also stays in place, written in
    // the old type (an ASCII attribute of a file made before UTF-8 strings).
    const bool same_string = old_type.ok() && H5Tget_class(old_type.get()) == H5T_STRING &&
                             H5Tget_class(type) == H5T_STRING &&
                             H5Tis_variable_str(old_type.get()) <= 0 &&
                             H5Tget_size(old_type.get()) == H5Tget_size(type);
    if (old.ok() && old_type.ok() && (same_string || H5Tequal(old_type.get(), type) > 0)) {
      if (H5Awrite(old.get(), same_string ? old_type.get() : type, value) < 0) {
        fail(fname, "cannot write attribute " + object + "@" + name);
      }
      return;
    }
    H5Adelete(obj.get(), name.c_str());
  }
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj.get(), name.c_str(), type, space.get(), H5P_DEFAULT,
                         H5P_DEFAULT),
              H5Aclose);
  if (!attr.ok() || H5Awrite(attr.get(), type, value) < 0) {
    fail(fname, "cannot write attribute " + object + "@" + name);
  }
}
}  // namespace

void File::set_attribute(const std::string& object, const std::string& name,
                         const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<std::size_t>(value.size(), 1));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);  // names and prose may hold any Unicode
  std::string padded = value.empty() ? std::string(1, '\0') : value;
  write_attribute(id_, path_, object, name, type.get(), padded.data());
}

void File::set_attribute(const std::string& object, const std::string& name,
                         double value) {
  write_attribute(id_, path_, object, name, H5T_NATIVE_DOUBLE, &value);
}

void File::set_attribute(const std::string& object, const std::string& name,
                         std::int64_t value) {
  write_attribute(id_, path_, object, name, H5T_NATIVE_INT64, &value);
}

bool File::has_attribute(const std::string& object, const std::string& name) const {
  if (!exists(object)) return false;
  Handle obj(open_object(id_, object), H5Oclose);
  return obj.ok() && H5Aexists(obj.get(), name.c_str()) > 0;
}

void File::remove_attribute(const std::string& object, const std::string& name) {
  if (!has_attribute(object, name)) return;
  Handle obj(open_object(id_, object), H5Oclose);
  if (H5Adelete(obj.get(), name.c_str()) < 0) fail(path_, "cannot delete " + object + "@" + name);
}

namespace {
Handle open_attribute(hid_t file, const std::string& fname, const std::string& object,
                      const std::string& name) {
  Handle obj(open_object(file, object), H5Oclose);
  if (!obj.ok()) fail(fname, "no object " + object);
  const hid_t attr = H5Aopen(obj.get(), name.c_str(), H5P_DEFAULT);
  if (attr < 0) fail(fname, "no attribute " + object + "@" + name);
  return Handle(attr, H5Aclose);
}
}  // namespace

std::string File::string_attribute(const std::string& object,
                                   const std::string& name) const {
  Handle attr = open_attribute(id_, path_, object, name);
  Handle type(H5Aget_type(attr.get()), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_STRING) {
    fail(path_, "attribute " + object + "@" + name + " is not a string");
  }
  if (H5Tis_variable_str(type.get()) > 0) {
    char* buffer = nullptr;
    Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mem.get(), H5T_VARIABLE);
    H5Tset_cset(mem.get(), H5Tget_cset(type.get()));  // ASCII or UTF-8, as stored
    if (H5Aread(attr.get(), mem.get(), &buffer) < 0) fail(path_, "cannot read " + name);
    std::string out = buffer ? buffer : "";
    H5free_memory(buffer);
    return out;
  }
  const std::size_t size = H5Tget_size(type.get());
  std::string out(size, '\0');
  if (H5Aread(attr.get(), type.get(), out.data()) < 0) fail(path_, "cannot read " + name);
  out.resize(std::strlen(out.c_str()));
  return out;
}

std::string File::attribute_bytes(const std::string& object, const std::string& name) const {
  Handle attr = open_attribute(id_, path_, object, name);
  Handle type(H5Aget_type(attr.get()), H5Tclose);
  if (H5Tget_class(type.get()) == H5T_STRING && H5Tis_variable_str(type.get()) > 0) {
    return string_attribute(object, name);
  }
  Handle space(H5Aget_space(attr.get()), H5Sclose);
  const hssize_t count = H5Sget_simple_extent_npoints(space.get());
  std::string out(static_cast<std::size_t>(std::max<hssize_t>(count, 0)) *
                      H5Tget_size(type.get()),
                  '\0');
  if (!out.empty() && H5Aread(attr.get(), type.get(), out.data()) < 0) {
    fail(path_, "cannot read attribute " + object + "@" + name);
  }
  return out;
}

double File::double_attribute(const std::string& object, const std::string& name) const {
  Handle attr = open_attribute(id_, path_, object, name);
  double v = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &v) < 0) fail(path_, "cannot read " + name);
  return v;
}

std::int64_t File::int_attribute(const std::string& object, const std::string& name) const {
  Handle attr = open_attribute(id_, path_, object, name);
  std::int64_t v = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_INT64, &v) < 0) fail(path_, "cannot read " + name);
  return v;
}

}  // namespace h5
}  // namespace phnn
