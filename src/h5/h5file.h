// src/h5/h5file.h — the only header of phnn that speaks HDF5. hid_t never
// leaves src/h5/*.cpp; HDF5 errors become phnn::h5::Error with the file name.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace phnn {
namespace h5 {

/// An HDF5 call failed; the message names the file and the object.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Access { kReadOnly, kReadWrite };

/// Element types of datasets.
enum class Type { kFloat64, kInt64, kString };

/// "HDF5 1.10.8" (the library linked at run time).
std::string library_version();

/// RAII HDF5 file. Serial (comm == MPI_COMM_NULL) or parallel (MPI-IO): in
/// parallel, create/open, create_dataset, attributes and close are
/// collective; write_rows/read are independent.
class File {
 public:
  /// Creates (truncates) `path`.
  static File create(const std::string& path, MPI_Comm comm = MPI_COMM_NULL);
  /// Opens an existing file; throws h5::Error if it is missing or not HDF5.
  static File open(const std::string& path, Access access,
                   MPI_Comm comm = MPI_COMM_NULL);
  /// True if `path` exists and is an HDF5 file.
  static bool is_hdf5(const std::string& path);

  File(File&& other) noexcept;
  File& operator=(File&& other) noexcept;
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  ~File();

  const std::string& path() const { return path_; }
  /// Writes what is pending and closes; throws h5::Error if that fails (the
  /// file is closed either way). Collective in parallel.
  void close();
  void flush();

  bool exists(const std::string& object) const;
  /// Creates every missing group along `group` ("a/b/c").
  void create_group(const std::string& group);
  /// Unlinks `object` (a group with everything under it, or a dataset);
  /// collective in parallel. A missing object is no error.
  void remove(const std::string& object);

  /// Attributes on an object ("/" for the file, a group or a dataset).
  void set_attribute(const std::string& object, const std::string& name,
                     const std::string& value);
  void set_attribute(const std::string& object, const std::string& name,
                     double value);
  void set_attribute(const std::string& object, const std::string& name,
                     std::int64_t value);
  bool has_attribute(const std::string& object, const std::string& name) const;
  /// Deletes attribute `name` of `object` (none: no error).
  void remove_attribute(const std::string& object, const std::string& name);
  /// Names of the attributes of `object`, in creation-index order if
  /// tracked, else by name.
  std::vector<std::string> attribute_names(const std::string& object) const;
  /// Names of the links (groups, datasets) in group `group`, by name.
  std::vector<std::string> link_names(const std::string& group) const;
  /// Every group and dataset below `group` (not `group` itself), as
  /// absolute paths ("/data/duffing/train/x"), sorted.
  std::vector<std::string> objects_under(const std::string& group) const;
  /// True if `object` is a dataset (false for a group or a missing path).
  bool is_dataset(const std::string& object) const;
  std::string string_attribute(const std::string& object,
                               const std::string& name) const;
  /// The stored bytes of an attribute's value, in the attribute's own type
  /// (a fixed-length string with its padding; a variable-length string's
  /// characters): what a checksum of every stored byte reads.
  std::string attribute_bytes(const std::string& object, const std::string& name) const;
  double double_attribute(const std::string& object,
                          const std::string& name) const;
  std::int64_t int_attribute(const std::string& object,
                             const std::string& name) const;

  /// Creates a contiguous dataset of `dims` (strings: fixed `string_length`
  /// bytes, NUL-padded), allocated and filled at creation: float64 elements
  /// with `fill_value` (e.g. NaN for "not written yet"), others with zeros.
  /// Collective in parallel.
  void create_dataset(const std::string& path, Type type,
                      const std::vector<std::uint64_t>& dims,
                      std::size_t string_length = 0, double fill_value = 0.0);
  /// A dataset of 64-bit integers with names (an HDF5 enum: value k is
  /// names[k]), allocated and filled with 0 like create_dataset; its rows
  /// are written and read as int64 (write_rows, read_ints).
  void create_enum_dataset(const std::string& path, const std::vector<std::uint64_t>& dims,
                           const std::vector<std::string>& names);
  std::vector<std::uint64_t> dims(const std::string& path) const;

  /// Writes rows [row, row + count) of a dataset (all trailing dimensions),
  /// independently. `data` holds count * prod(dims[1:]) elements.
  void write_rows(const std::string& path, std::uint64_t row,
                  std::uint64_t count, const double* data);
  void write_rows(const std::string& path, std::uint64_t row,
                  std::uint64_t count, const std::int64_t* data);
  void write_string_rows(const std::string& path, std::uint64_t row,
                         const std::vector<std::string>& values);

  /// Whole-dataset convenience: create + write (serial files, or every rank
  /// passing the same data in parallel: rank 0 writes).
  void write(const std::string& path, const std::vector<std::uint64_t>& dims,
             const std::vector<double>& data);
  void write(const std::string& path, const std::vector<std::uint64_t>& dims,
             const std::vector<std::int64_t>& data);

  /// Reads rows [row, row + count) (count = 0: to the end).
  std::vector<double> read_doubles(const std::string& path,
                                   std::uint64_t row = 0,
                                   std::uint64_t count = 0) const;
  std::vector<std::int64_t> read_ints(const std::string& path,
                                      std::uint64_t row = 0,
                                      std::uint64_t count = 0) const;
  /// The stored bytes of rows [row, row + count) (count = 0: to the end) in
  /// the dataset's own type: fixed-length strings with their padding,
  /// numbers in the file's byte order. What a checksum of every stored byte
  /// reads.
  std::string read_row_bytes(const std::string& path, std::uint64_t row = 0,
                             std::uint64_t count = 0) const;
  /// Where the data of a contiguous dataset start in the file, in bytes
  /// (tests damage bytes there); throws if it has no such address.
  std::uint64_t data_address(const std::string& path) const;
  /// Fixed-length strings without their NUL padding; rows as above.
  std::vector<std::string> read_strings(const std::string& path,
                                        std::uint64_t row = 0,
                                        std::uint64_t count = 0) const;

 private:
  File(std::int64_t id, std::string path, MPI_Comm comm);
  std::int64_t id_ = -1;
  std::string path_;
  MPI_Comm comm_ = MPI_COMM_NULL;
};

}  // namespace h5
}  // namespace phnn
