// src/h5/h5file_datasets.cpp — h5::File datasets: creation (contiguous,
// allocated and filled early), dimensions, and row reads and writes of
// doubles, int64 and fixed-length strings.
#include <cstring>
#include <numeric>
#include <sstream>

#include "h5/h5_handle.h"

namespace phnn {
namespace h5 {

using namespace detail;

namespace {
Handle string_type(std::size_t length) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<std::size_t>(length, 1));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);  // reads use the stored type: old ASCII files too
  return type;
}

// Contiguous, allocated and filled at creation, so independent writes of
// rows later never change file metadata.
Handle early_allocated_layout() {
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_layout(dcpl.get(), H5D_CONTIGUOUS);
  H5Pset_alloc_time(dcpl.get(), H5D_ALLOC_TIME_EARLY);
  H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_ALLOC);
  return dcpl;
}
}  // namespace

void File::create_enum_dataset(const std::string& path, const std::vector<std::uint64_t>& dims,
                               const std::vector<std::string>& names) {
  const auto slash = path.rfind('/');
  if (slash != std::string::npos && slash > 0) create_group(path.substr(0, slash));
  Handle type(H5Tenum_create(H5T_STD_I64LE), H5Tclose);
  for (std::size_t v = 0; v < names.size(); ++v) {
    const std::int64_t value = static_cast<std::int64_t>(v);
    if (H5Tenum_insert(type.get(), names[v].c_str(), &value) < 0) {
      fail(path_, "cannot define enum value " + names[v] + " of " + path);
    }
  }
  std::vector<hsize_t> hdims(dims.begin(), dims.end());
  Handle space(H5Screate_simple(static_cast<int>(hdims.size()), hdims.data(), nullptr),
               H5Sclose);
  Handle dcpl = early_allocated_layout();  // filled with zeros: the first name
  Handle dset(H5Dcreate2(id_, path.c_str(), type.get(), space.get(), H5P_DEFAULT, dcpl.get(),
                         H5P_DEFAULT),
              H5Dclose);
  if (!dset.ok()) fail(path_, "cannot create dataset " + path);
}

void File::create_dataset(const std::string& path, Type type,
                          const std::vector<std::uint64_t>& dims,
                          std::size_t string_length, double fill_value) {
  const auto slash = path.rfind('/');
  if (slash != std::string::npos && slash > 0) create_group(path.substr(0, slash));
  std::vector<hsize_t> hdims(dims.begin(), dims.end());
  Handle space(H5Screate_simple(static_cast<int>(hdims.size()), hdims.data(), nullptr),
               H5Sclose);
  Handle dcpl = early_allocated_layout();
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
// Dataset `path` of `file`, open (throws naming the file if it is not there).
Handle open_dataset(hid_t file, const std::string& fname, const std::string& path) {
  Handle dset(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dset.ok()) fail(fname, "no dataset " + path);
  return dset;
}

// Rows [row, row + count) of the open dataset `dset` (named `path`): read
// or written; count 0 on a read: to the end. *count_out gets the count.
void dataset_rows_io(const Handle& dset, const std::string& fname, const std::string& path,
                     std::uint64_t row, std::uint64_t count, hid_t memtype, void* data,
                     bool write, std::uint64_t* count_out = nullptr) {
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
  // An enum of 64-bit integers (create_enum_dataset) moves as int64: HDF5
  // converts no integers to enums, so the memory type is the enum itself
  // (same bytes as int64_t).
  Handle stored(H5Dget_type(dset.get()), H5Tclose);
  hid_t enum_type = -1;
  if (memtype == H5T_NATIVE_INT64 && H5Tget_class(stored.get()) == H5T_ENUM &&
      H5Tget_size(stored.get()) == sizeof(std::int64_t)) {
    enum_type = H5Tget_native_type(stored.get(), H5T_DIR_ASCEND);
    memtype = enum_type;
  }
  const Handle native_enum(enum_type, H5Tclose);  // closed on return (if opened)
  const herr_t status =
      write ? H5Dwrite(dset.get(), memtype, mspace.get(), fspace.get(), H5P_DEFAULT, data)
            : H5Dread(dset.get(), memtype, mspace.get(), fspace.get(), H5P_DEFAULT, data);
  if (status < 0) {
    std::ostringstream msg;
    msg << (write ? "H5Dwrite" : "H5Dread") << " failed for " << path << " rows ["
        << row << ", " << row + count << ")";
    fail(fname, msg.str());
  }
}

void rows_io(hid_t file, const std::string& fname, const std::string& path,
             std::uint64_t row, std::uint64_t count, hid_t memtype, void* data,
             bool write, std::uint64_t* count_out = nullptr) {
  dataset_rows_io(open_dataset(file, fname, path), fname, path, row, count, memtype, data, write,
                  count_out);
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
  const Handle dset = open_dataset(id_, path_, path);
  Handle type(H5Dget_type(dset.get()), H5Tclose);
  const std::size_t length = H5Tget_size(type.get());
  std::vector<char> buffer(values.size() * length, '\0');
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::memcpy(buffer.data() + i * length, values[i].data(),
                std::min(length, values[i].size()));
  }
  dataset_rows_io(dset, path_, path, row, values.size(), type.get(), buffer.data(), true);
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

namespace {
// Rows [row, row + count) of dataset `path` (count 0: to the end), of
// element type T (memtype), the dataset opened once.
template <class T>
std::vector<T> read_rows(hid_t file, const std::string& fname, const std::string& path,
                         std::uint64_t row, std::uint64_t count, hid_t memtype) {
  const Handle dset = open_dataset(file, fname, path);
  std::uint64_t n = 0;
  dataset_rows_io(dset, fname, path, row, count, memtype, nullptr, false, &n);
  std::vector<T> out(n * row_size(dataset_dims(dset.get())));
  dataset_rows_io(dset, fname, path, row, n, memtype, out.data(), false);
  return out;
}
}  // namespace

std::vector<double> File::read_doubles(const std::string& path, std::uint64_t row,
                                       std::uint64_t count) const {
  return read_rows<double>(id_, path_, path, row, count, H5T_NATIVE_DOUBLE);
}

std::vector<std::int64_t> File::read_ints(const std::string& path, std::uint64_t row,
                                          std::uint64_t count) const {
  return read_rows<std::int64_t>(id_, path_, path, row, count, H5T_NATIVE_INT64);
}

std::string File::read_row_bytes(const std::string& path, std::uint64_t row,
                                 std::uint64_t count) const {
  const Handle dset = open_dataset(id_, path_, path);
  Handle type(H5Dget_type(dset.get()), H5Tclose);
  std::vector<hsize_t> d = dataset_dims(dset.get());
  std::uint64_t rows = 0;
  dataset_rows_io(dset, path_, path, row, count, type.get(), nullptr, false, &rows);
  std::string out(rows * row_size(d) * H5Tget_size(type.get()), '\0');
  dataset_rows_io(dset, path_, path, row, rows, type.get(), out.data(), false);
  return out;
}

std::uint64_t File::data_address(const std::string& path) const {
  Handle dset(H5Dopen2(id_, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dset.ok()) fail(path_, "no dataset " + path);
  const haddr_t address = H5Dget_offset(dset.get());
  if (address == HADDR_UNDEF) fail(path_, "dataset " + path + " has no contiguous data address");
  return static_cast<std::uint64_t>(address);
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
    dataset_rows_io(dset, path_, path, row, count, type.get(), nullptr, false, &rows);
    n = rows;
    buffer.assign(n * length, '\0');
    dataset_rows_io(dset, path_, path, row, n, type.get(), buffer.data(), false);
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
