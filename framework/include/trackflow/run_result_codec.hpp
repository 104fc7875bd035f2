// Purpose: the optional interface of a component whose per-run results can cross process boundaries (trackflow run under mpirun): it writes its RunResult as bytes and reads them back, exactly — by hand, or from the result's one field list (FieldListCodec).
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

// A per-run result lists its fields once, for both directions (see FieldListCodec below):
//   template <class Self, class F> static void fields(Self& r, F&& f) { f(r.a, r.b, r.c); }
// Self is `const R` when writing and `R` when reading. Any struct with such a list is a
// "field record"; records may nest and may be the elements of a std::vector.
struct AnyFieldList {
  template <class... Ts>
  void operator()(Ts&...) const {}
};
template <class T>
concept FieldRecord = requires(T& r) { T::fields(r, AnyFieldList{}); };

namespace codec_detail {
template <class T>
inline constexpr bool is_vector = false;
template <class T, class A>
inline constexpr bool is_vector<std::vector<T, A>> = true;
// (The member check first: MatrixBase<T> of a non-Eigen T must not be instantiated.)
template <class T>
concept EigenMatrix = requires { T::RowsAtCompileTime; T::MaxRowsAtCompileTime; } &&
                      std::is_base_of_v<Eigen::MatrixBase<T>, T>;
template <class T>
inline constexpr bool is_fixed_eigen = T::RowsAtCompileTime != Eigen::Dynamic && T::ColsAtCompileTime != Eigen::Dynamic;
}  // namespace codec_detail

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
  // Each value by its type, in order (ByteReader::get_all reads them back): a field record -> its
  // fields; an Eigen matrix -> put_matrix (a run-time size is written first); std::string ->
  // put_string; std::vector -> put_vector, or (elements not trivially copyable, e.g. records) its
  // size and then each element; anything else trivially copyable (numbers, enums, bool, arrays,
  // plain structs) -> put.
  template <class... Ts>
  void put_all(const Ts&... v) {
    (put_one(v), ...);
  }

 private:
  template <class T>
  void put_one(const T& v) {
    if constexpr (FieldRecord<T>) {
      T::fields(v, [&w = *this](const auto&... f) { w.put_all(f...); });
    } else if constexpr (codec_detail::EigenMatrix<T>) {
      if constexpr (!codec_detail::is_fixed_eigen<T>) {
        put(static_cast<std::uint64_t>(v.rows()));
        put(static_cast<std::uint64_t>(v.cols()));
      }
      put_matrix(v);
    } else if constexpr (std::is_same_v<T, std::string>) {
      put_string(v);
    } else if constexpr (codec_detail::is_vector<T>) {
      if constexpr (std::is_trivially_copyable_v<typename T::value_type>) {
        put_vector(v);
      } else {
        put(static_cast<std::uint64_t>(v.size()));
        for (const auto& e : v) put_one(e);
      }
    } else {
      static_assert(std::is_trivially_copyable_v<T>,
                    "put_all(): give this type a fields() list, or write it with the put_* calls");
      put(v);
    }
  }
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
  // Reads back what ByteWriter::put_all wrote, the same types in the same order.
  template <class... Ts>
  void get_all(Ts&... v) {
    (get_one(v), ...);
  }
  bool done() const { return p_ == end_; }

 private:
  template <class T>
  void get_one(T& v) {
    if constexpr (FieldRecord<T>) {
      T::fields(v, [&r = *this](auto&... f) { r.get_all(f...); });
    } else if constexpr (codec_detail::EigenMatrix<T>) {
      if constexpr (!codec_detail::is_fixed_eigen<T>) {
        const auto rows = get<std::uint64_t>(), cols = get<std::uint64_t>();
        // Checked before resizing: a corrupt size must not allocate (or overflow a bounded matrix).
        const auto fits = [](std::uint64_t n, int fixed, int max) {
          return (fixed == Eigen::Dynamic || n == static_cast<std::uint64_t>(fixed)) &&
                 (max == Eigen::Dynamic || n <= static_cast<std::uint64_t>(max));
        };
        if (!fits(rows, T::RowsAtCompileTime, T::MaxRowsAtCompileTime) ||
            !fits(cols, T::ColsAtCompileTime, T::MaxColsAtCompileTime) ||
            (cols && rows > static_cast<std::uint64_t>(end_ - p_) / sizeof(double) / cols))
          fail();
        v.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
      }
      get_matrix(v);
    } else if constexpr (std::is_same_v<T, std::string>) {
      v = get_string();
    } else if constexpr (codec_detail::is_vector<T>) {
      if constexpr (std::is_trivially_copyable_v<typename T::value_type>) {
        get_vector(v);
      } else {
        const auto n = get<std::uint64_t>();
        need(n);  // every record is at least one byte: a corrupt count must not allocate
        v.resize(n);
        for (auto& e : v) get_one(e);
      }
    } else {
      static_assert(std::is_trivially_copyable_v<T>,
                    "get_all(): give this type a fields() list, or read it with the get_* calls");
      get(v);
    }
  }
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

// The codec of a result type R that lists its fields once (a FieldRecord, above): a component
// derives from FieldListCodec<R> instead of RunResultCodec and writes no save/load of its own.
// Why: a hand-written save_run_result and load_run_result are the same list written twice, and
// when they drift (a field added to one, or to the struct only) the merged result differs under
// mpirun and nowhere else; one list cannot drift. Byte format: put_all's. A component whose
// result needs more than the list (sizes to check, data outside the struct) may still override
// load_run_result and call `in.get_all(*r)` there.
template <FieldRecord R>
class FieldListCodec : public RunResultCodec {
 public:
  void save_run_result(const RunResult& result, ByteWriter& out) const override { save_fields(result, out); }
  std::unique_ptr<RunResult> load_run_result(ByteReader& in) const override { return load_fields(in); }

  // The two directions on their own, for a class whose bases are fixed (FilterFrontEnd).
  static void save_fields(const RunResult& result, ByteWriter& out) { out.put_all(static_cast<const R&>(result)); }
  static std::unique_ptr<R> load_fields(ByteReader& in) {
    auto r = std::make_unique<R>();
    in.get_all(*r);
    return r;
  }
};

}  // namespace trackflow
