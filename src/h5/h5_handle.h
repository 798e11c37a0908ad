// src/h5/h5_handle.h — shared by h5file.cpp and h5file_datasets.cpp only:
// RAII for HDF5 identifiers and the small helpers around the C API.
#pragma once

#include <hdf5.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "h5/h5file.h"

namespace phnn {
namespace h5 {
namespace detail {

static_assert(sizeof(hid_t) == sizeof(std::int64_t), "hid_t must be 64-bit");

// Silences HDF5's own error stack printing: we report errors ourselves.
// And no cleanup at exit: phnn closes every file itself, and HDF5's own
// atexit cleanup crashes on a file whose close failed (a full disk).
struct SilenceHdf5 {
  SilenceHdf5() {
    H5dont_atexit();
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
};

// The operating system's words for the failure on HDF5's error stack, e.g.
// "No space left on device" ("" if the failure was not a system call's).
inline std::string system_error_text() {
  std::string text;
  auto visit = [](unsigned, const H5E_error2_t* e, void* data) -> herr_t {
    const std::string desc = e->desc != nullptr ? e->desc : "";
    const std::size_t at = desc.find("error message = '");
    if (at != std::string::npos) {
      const std::size_t begin = at + 17;
      *static_cast<std::string*>(data) = desc.substr(begin, desc.find('\'', begin) - begin);
    }
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, visit, &text);
  return text;
}

// Throws Error("<file>: <what>: <the system's reason>"), or with `hint`
// instead of the reason when the failure was not a system call's.
[[noreturn]] inline void fail(const std::string& file, const std::string& what,
                              const std::string& hint = "") {
  const std::string system = system_error_text();
  throw Error(file + ": " + what +
              (!system.empty() ? ": " + system : hint.empty() ? "" : "; " + hint));
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

inline hid_t file_access_plist(MPI_Comm comm) {
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  if (comm != MPI_COMM_NULL) H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
  return fapl;
}

inline hid_t open_object(hid_t file, const std::string& path) {
  return H5Oopen(file, path.c_str(), H5P_DEFAULT);
}

inline std::uint64_t row_size(const std::vector<hsize_t>& dims) {
  std::uint64_t n = 1;
  for (std::size_t i = 1; i < dims.size(); ++i) n *= dims[i];
  return n;
}

inline std::vector<hsize_t> dataset_dims(hid_t dset) {
  Handle space(H5Dget_space(dset), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

}  // namespace detail
}  // namespace h5
}  // namespace phnn
