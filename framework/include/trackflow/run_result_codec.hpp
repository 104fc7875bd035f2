// Purpose: the optional interface of a component whose per-run results can cross process boundaries (trackflow run under mpirun): it writes its RunResult as bytes and reads them back, exactly.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/error.hpp>

#include <boost/config.hpp>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace trackflow {

// Appends values to a byte string. Numbers are copied bit for bit (a double arrives exactly as
// it left, so merged sums are the same as in one process); the processes of one job run the
// same build on the same architecture (checked by the engine).
class ByteWriter {
 public:
  explicit ByteWriter(std::string& out) : out_(out) {}
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>, "put() copies bytes: use a field-by-field overload");
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void put_doubles(const double* v, std::size_t n) { out_.append(reinterpret_cast<const char*>(v), n * sizeof(double)); }
  // Any fixed- or run-time-sized Eigen matrix of doubles (its size is the reader's to know).
  template <class Matrix>
  void put_matrix(const Matrix& m) {
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i) put(static_cast<double>(m(i, j)));
  }
  void put_string(const std::string& s) {
    put(static_cast<std::uint64_t>(s.size()));
    out_.append(s);
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>, "put_vector() copies bytes: write the elements one by one");
    put(static_cast<std::uint64_t>(v.size()));
    if (!v.empty()) out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }

 private:
  std::string& out_;
};

// Reads what a ByteWriter wrote; running past the end throws DataError (a truncated message).
class ByteReader {
 public:
  ByteReader(const char* data, std::size_t size) : p_(data), end_(data + size) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    take(&v, sizeof(T));
    return v;
  }
  template <class T>
  void get(T& v) {  // also arrays
    static_assert(std::is_trivially_copyable_v<T>);
    take(&v, sizeof(T));
  }
  void get_doubles(double* v, std::size_t n) { take(v, n * sizeof(double)); }
  template <class Matrix>
  void get_matrix(Matrix& m) {
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i) m(i, j) = get<double>();
  }
  std::string get_string() {
    const auto n = get<std::uint64_t>();
    need(n);
    std::string s(p_, p_ + n);
    p_ += n;
    return s;
  }
  template <class T>
  void get_vector(std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto n = get<std::uint64_t>();
    if (n > static_cast<std::uint64_t>(end_ - p_) / (sizeof(T) ? sizeof(T) : 1)) fail();
    v.resize(n);
    take(v.data(), n * sizeof(T));
  }
  bool done() const { return p_ == end_; }

 private:
  void need(std::uint64_t n) const {
    if (n > static_cast<std::uint64_t>(end_ - p_)) fail();
  }
  [[noreturn]] static void fail() { throw DataError("a per-run result received from another process is truncated"); }
  void take(void* dst, std::size_t n) {
    need(n);
    if (n) std::memcpy(dst, p_, n);
    p_ += n;
  }
  const char* p_;
  const char* end_;
};

// Implemented (besides Component) by a component whose end_run() returns a RunResult, so that the
// result of a run computed in one process can be merged by the component's instance in another:
// `mpirun -np N trackflow run` has every process run some of the runs and the first one merge
// all of them in run order. A component without it still runs in one process (any --threads);
// under mpirun the engine refuses it by name as soon as it returns a result. Adding this
// interface changes no existing type, so plugins built without it keep loading (same ABI).
class BOOST_SYMBOL_VISIBLE RunResultCodec {
 public:
  virtual ~RunResultCodec() = default;
  // Writes `result` (what this component's end_run() returned; never null) to `out`.
  virtual void save_run_result(const RunResult& result, ByteWriter& out) const = 0;
  // Rebuilds it from what save_run_result wrote, on an instance of the same node.
  virtual std::unique_ptr<RunResult> load_run_result(ByteReader& in) const = 0;
};

}  // namespace trackflow
