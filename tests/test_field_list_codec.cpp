// Purpose: the one-list codec of run_result_codec.hpp (put_all / get_all / FieldListCodec): every kind of field a per-run result holds comes back exactly, and a truncated or corrupt message throws DataError.
#include <trackflow/run_result_codec.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

enum class Colour : std::uint8_t { Red, Blue };

struct Point {  // trivially copyable: a vector of it goes as one block
  double t = 0.0;
  std::uint32_t id = 0;
};

struct Stream {  // a record inside a vector
  Colour colour = Colour::Red;
  std::vector<Point> points;
  template <class Self, class F>
  static void fields(Self& s, F&& f) {
    f(s.colour, s.points);
  }
};

struct Everything final : RunResult {
  bool flag = false;
  std::uint64_t count = 0;
  double sum = 0.0;
  std::uint64_t table[2][3] = {};
  Eigen::Matrix<double, 3, 2> fixed = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::MatrixXd dynamic;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1> bounded;
  std::string text;
  std::vector<double> values;
  std::vector<Stream> streams;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.flag, r.count, r.sum, r.table, r.fixed, r.dynamic, r.bounded, r.text, r.values, r.streams);
  }
};

static_assert(FieldRecord<Everything> && FieldRecord<Stream> && !FieldRecord<Point>);

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

Everything sample() {
  Everything e;
  e.flag = true;
  e.count = 0x0123456789abcdefULL;
  e.sum = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j) e.table[i][j] = 10u * i + j + 1;
  e.fixed << 1, 2, 3, 4, 5, -0.0;
  e.dynamic.resize(2, 3);
  e.dynamic << 1.0 / 3.0, 2, 3, 4, 5, 6;
  e.bounded.resize(2);
  e.bounded << 7, 8;
  e.text = std::string("run 3\0, t=1.5", 13);
  e.values = {0.1, std::numeric_limits<double>::denorm_min(), -1e300};
  e.streams.resize(2);
  e.streams[0].colour = Colour::Blue;
  e.streams[0].points = {{0.5, 1}, {1.5, 2}};
  return e;
}

void check_same(const Everything& a, const Everything& b) {
  CHECK(a.flag == b.flag);
  CHECK(a.count == b.count);
  CHECK(same_bits(a.sum, b.sum));
  CHECK(std::memcmp(a.table, b.table, sizeof a.table) == 0);
  CHECK(a.fixed == b.fixed);
  CHECK(std::signbit(b.fixed(2, 1)));
  REQUIRE(b.dynamic.rows() == 2);
  REQUIRE(b.dynamic.cols() == 3);
  CHECK(a.dynamic == b.dynamic);
  REQUIRE(b.bounded.size() == 2);
  CHECK(a.bounded == b.bounded);
  CHECK(a.text == b.text);
  REQUIRE(b.values.size() == a.values.size());
  for (size_t i = 0; i < a.values.size(); ++i) CHECK(same_bits(a.values[i], b.values[i]));
  REQUIRE(b.streams.size() == 2);
  CHECK(b.streams[0].colour == Colour::Blue);
  REQUIRE(b.streams[0].points.size() == 2);
  CHECK(b.streams[0].points[1].t == 1.5);
  CHECK(b.streams[0].points[1].id == 2);
  CHECK(b.streams[1].colour == Colour::Red);
  CHECK(b.streams[1].points.empty());
}

struct Codec final : FieldListCodec<Everything> {};

std::string encoded(const Everything& e) {
  std::string bytes;
  ByteWriter w(bytes);
  Codec{}.save_run_result(e, w);
  return bytes;
}

}  // namespace

TEST_CASE("a field list round-trips every kind of field") {
  const Everything e = sample();
  const std::string bytes = encoded(e);
  ByteReader in(bytes.data(), bytes.size());
  const auto back = Codec{}.load_run_result(in);
  CHECK(in.done());
  check_same(e, static_cast<const Everything&>(*back));
}

TEST_CASE("put_all writes the bytes of the matching put calls") {
  // The format is the put_* calls': a codec converted to a field list keeps its bytes.
  const Everything e = sample();
  std::string bytes;
  ByteWriter w(bytes);
  w.put(e.flag);
  w.put(e.count);
  w.put(e.sum);
  w.put(e.table);
  w.put_matrix(e.fixed);
  w.put(std::uint64_t{2});
  w.put(std::uint64_t{3});
  w.put_matrix(e.dynamic);
  w.put(std::uint64_t{2});
  w.put(std::uint64_t{1});
  w.put_matrix(e.bounded);
  w.put_string(e.text);
  w.put_vector(e.values);
  w.put(std::uint64_t{2});
  for (const auto& s : e.streams) {
    w.put(s.colour);
    w.put_vector(s.points);
  }
  CHECK(bytes == encoded(e));
}

TEST_CASE("a truncated field list throws DataError at every cut") {
  const std::string bytes = encoded(sample());
  for (size_t n = 0; n < bytes.size(); ++n) {
    ByteReader in(bytes.data(), n);
    CHECK_THROWS_AS(Codec{}.load_run_result(in), DataError);
  }
}

TEST_CASE("a corrupt size in a field list throws instead of allocating") {
  std::string bytes = encoded(sample());
  // The dynamic matrix's row count follows flag, count, sum, table and the 3x2 matrix.
  const size_t at = sizeof(bool) + 8 + 8 + sizeof(std::uint64_t[2][3]) + 6 * 8;
  for (std::uint64_t rows : {std::uint64_t{1} << 40, ~std::uint64_t{0}}) {
    std::memcpy(bytes.data() + at, &rows, 8);
    ByteReader in(bytes.data(), bytes.size());
    CHECK_THROWS_AS(Codec{}.load_run_result(in), DataError);
  }
  // A bounded matrix refuses more rows than its maximum (4).
  std::string big = encoded(sample());
  const size_t bounded_at = at + 16 + 6 * 8;
  const std::uint64_t five = 5;
  std::memcpy(big.data() + bounded_at, &five, 8);
  ByteReader in(big.data(), big.size());
  CHECK_THROWS_AS(Codec{}.load_run_result(in), DataError);
}
