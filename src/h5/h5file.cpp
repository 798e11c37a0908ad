// src/h5/h5file.cpp
#include "h5/h5file.h"

#include <hdf5.h>

#include <cstring>
#include <fstream>
#include <numeric>
#include <sstream>

namespace phnn {
namespace h5 {
namespace {

static_assert(sizeof(hid_t) == sizeof(std::int64_t), "hid_t must be 64-bit");

// Silences HDF5's own error stack printing: we report errors ourselves.
struct SilenceHdf5 {
  SilenceHdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }
};
const SilenceHdf5 kSilence;

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw Error(file + ": " + what);
}

// RAII for one HDF5 identifier.
class Handle {
 public:
  Handle(hid_t id, herr_t (*closer)(hid_t)) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = -1; }
  ~Handle() {
    if (id_ >= 0) closer_(id_);
  }
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*closer_)(hid_t);
};

hid_t file_access_plist(MPI_Comm comm) {
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  if (comm != MPI_COMM_NULL) H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
  return fapl;
}

hid_t open_object(hid_t file, const std::string& path) {
  return H5Oopen(file, path.c_str(), H5P_DEFAULT);
}

std::uint64_t row_size(const std::vector<hsize_t>& dims) {
  std::uint64_t n = 1;
  for (std::size_t i = 1; i < dims.size(); ++i) n *= dims[i];
  return n;
}

std::vector<hsize_t> dataset_dims(hid_t dset) {
  Handle space(H5Dget_space(dset), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

}  // namespace

File::File(std::int64_t id, std::string path, MPI_Comm comm)
    : id_(id), path_(std::move(path)), comm_(comm) {}

File File::create(const std::string& path, MPI_Comm comm) {
  Handle fapl(file_access_plist(comm), H5Pclose);
  const hid_t id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get());
  if (id < 0) fail(path, "cannot create the HDF5 file; is the directory writable?");
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
  if (id < 0) fail(path, "cannot open the HDF5 file (locked by another process?)");
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
  if (id_ >= 0) {
    H5Fclose(id_);
    id_ = -1;
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
  if (H5Aexists(obj.get(), name.c_str()) > 0) H5Adelete(obj.get(), name.c_str());
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

namespace {
Handle string_type(std::size_t length) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<std::size_t>(length, 1));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  return type;
}
}  // namespace

void File::create_dataset(const std::string& path, Type type,
                          const std::vector<std::uint64_t>& dims,
                          std::size_t string_length, double fill_value) {
  const auto slash = path.rfind('/');
  if (slash != std::string::npos && slash > 0) create_group(path.substr(0, slash));
  std::vector<hsize_t> hdims(dims.begin(), dims.end());
  Handle space(H5Screate_simple(static_cast<int>(hdims.size()), hdims.data(), nullptr),
               H5Sclose);
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_layout(dcpl.get(), H5D_CONTIGUOUS);
  // Allocate at creation so independent writes never change file metadata.
  H5Pset_alloc_time(dcpl.get(), H5D_ALLOC_TIME_EARLY);
  H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_ALLOC);
  hid_t h5type = H5T_NATIVE_DOUBLE;
  Handle stype = string_type(string_length);
  if (type == Type::kInt64) h5type = H5T_NATIVE_INT64;
  if (type == Type::kString) h5type = stype.get();
  if (type == Type::kFloat64) {
    H5Pset_fill_value(dcpl.get(), H5T_NATIVE_DOUBLE, &fill_value);
  }
  Handle dset(H5Dcreate2(id_, path.c_str(), h5type, space.get(), H5P_DEFAULT,
                         dcpl.get(), H5P_DEFAULT),
              H5Dclose);
  if (!dset.ok()) fail(path_, "cannot create dataset " + path);
}

std::vector<std::uint64_t> File::dims(const std::string& path) const {
  Handle dset(H5Dopen2(id_, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dset.ok()) fail(path_, "no dataset " + path);
  const auto d = dataset_dims(dset.get());
  return std::vector<std::uint64_t>(d.begin(), d.end());
}

namespace {
void rows_io(hid_t file, const std::string& fname, const std::string& path,
             std::uint64_t row, std::uint64_t count, hid_t memtype, void* data,
             bool write, std::uint64_t* count_out = nullptr) {
  Handle dset(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dset.ok()) fail(fname, "no dataset " + path);
  std::vector<hsize_t> dims = dataset_dims(dset.get());
  if (dims.empty()) dims = {1};
  if (count == 0 && !write) count = dims[0] - std::min<hsize_t>(row, dims[0]);
  if (row + count > dims[0]) {
    std::ostringstream msg;
    msg << "rows [" << row << ", " << row + count << ") outside dataset " << path
        << " with " << dims[0] << " rows";
    fail(fname, msg.str());
  }
  if (count_out) *count_out = count;
  if (count == 0 || data == nullptr) return;
  Handle fspace(H5Dget_space(dset.get()), H5Sclose);
  std::vector<hsize_t> start(dims.size(), 0), extent = dims;
  start[0] = row;
  extent[0] = count;
  H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start.data(), nullptr,
                      extent.data(), nullptr);
  Handle mspace(H5Screate_simple(static_cast<int>(extent.size()), extent.data(), nullptr),
                H5Sclose);
  Handle dxpl(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
  const herr_t status =
      write ? H5Dwrite(dset.get(), memtype, mspace.get(), fspace.get(), dxpl.get(), data)
            : H5Dread(dset.get(), memtype, mspace.get(), fspace.get(), dxpl.get(), data);
  if (status < 0) {
    std::ostringstream msg;
    msg << (write ? "H5Dwrite" : "H5Dread") << " failed for " << path << " rows ["
        << row << ", " << row + count << ")";
    fail(fname, msg.str());
  }
}
}  // namespace

void File::write_rows(const std::string& path, std::uint64_t row,
                      std::uint64_t count, const double* data) {
  rows_io(id_, path_, path, row, count, H5T_NATIVE_DOUBLE, const_cast<double*>(data), true);
}

void File::write_rows(const std::string& path, std::uint64_t row,
                      std::uint64_t count, const std::int64_t* data) {
  rows_io(id_, path_, path, row, count, H5T_NATIVE_INT64,
          const_cast<std::int64_t*>(data), true);
}

void File::write_string_rows(const std::string& path, std::uint64_t row,
                             const std::vector<std::string>& values) {
  Handle dset(H5Dopen2(id_, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dset.ok()) fail(path_, "no dataset " + path);
  Handle type(H5Dget_type(dset.get()), H5Tclose);
  const std::size_t length = H5Tget_size(type.get());
  std::vector<char> buffer(values.size() * length, '\0');
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::memcpy(buffer.data() + i * length, values[i].data(),
                std::min(length, values[i].size()));
  }
  rows_io(id_, path_, path, row, values.size(), type.get(), buffer.data(), true);
}

void File::write(const std::string& path, const std::vector<std::uint64_t>& dims,
                 const std::vector<double>& data) {
  create_dataset(path, Type::kFloat64, dims);
  int rank = 0;
  if (comm_ != MPI_COMM_NULL) MPI_Comm_rank(comm_, &rank);
  if (rank == 0) write_rows(path, 0, dims.empty() ? 1 : dims[0], data.data());
}

void File::write(const std::string& path, const std::vector<std::uint64_t>& dims,
                 const std::vector<std::int64_t>& data) {
  create_dataset(path, Type::kInt64, dims);
  int rank = 0;
  if (comm_ != MPI_COMM_NULL) MPI_Comm_rank(comm_, &rank);
  if (rank == 0) write_rows(path, 0, dims.empty() ? 1 : dims[0], data.data());
}

std::vector<double> File::read_doubles(const std::string& path, std::uint64_t row,
                                       std::uint64_t count) const {
  std::uint64_t n = 0;
  rows_io(id_, path_, path, row, count, H5T_NATIVE_DOUBLE, nullptr, false, &n);
  const auto d = dims(path);
  std::vector<hsize_t> hd(d.begin(), d.end());
  std::vector<double> out(n * row_size(hd));
  rows_io(id_, path_, path, row, n, H5T_NATIVE_DOUBLE, out.data(), false);
  return out;
}

std::vector<std::int64_t> File::read_ints(const std::string& path, std::uint64_t row,
                                          std::uint64_t count) const {
  std::uint64_t n = 0;
  rows_io(id_, path_, path, row, count, H5T_NATIVE_INT64, nullptr, false, &n);
  const auto d = dims(path);
  std::vector<hsize_t> hd(d.begin(), d.end());
  std::vector<std::int64_t> out(n * row_size(hd));
  rows_io(id_, path_, path, row, n, H5T_NATIVE_INT64, out.data(), false);
  return out;
}

std::vector<std::string> File::read_strings(const std::string& path, std::uint64_t row,
                                            std::uint64_t count) const {
  Handle dset(H5Dopen2(id_, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dset.ok()) fail(path_, "no dataset " + path);
  Handle type(H5Dget_type(dset.get()), H5Tclose);
  const std::size_t length = H5Tget_size(type.get());
  const auto d = dataset_dims(dset.get());
  std::size_t n = d.empty() ? 1 : d[0];
  std::vector<char> buffer;
  if (row == 0 && count == 0) {  // the whole dataset (scalar ones too)
    buffer.assign(n * length, '\0');
    if (n > 0 && H5Dread(dset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT,
                         buffer.data()) < 0) {
      fail(path_, "cannot read " + path);
    }
  } else {
    std::uint64_t rows = 0;
    rows_io(id_, path_, path, row, count, type.get(), nullptr, false, &rows);
    n = rows;
    buffer.assign(n * length, '\0');
    rows_io(id_, path_, path, row, n, type.get(), buffer.data(), false);
  }
  std::vector<std::string> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* s = buffer.data() + i * length;
    out[i] = std::string(s, strnlen(s, length));
  }
  return out;
}

}  // namespace h5
}  // namespace phnn
