// Purpose: tests of csv::LineStream and csv::content_end against a plain in-memory splitter, across buffer boundaries and growth.
#include "csv_text.hpp"

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

// A file holding `text`, open for reading, removed at the end.
class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    char name[] = "/tmp/trackflow_line_stream_XXXXXX";
    fd_ = ::mkstemp(name);
    REQUIRE(fd_ >= 0);
    path_ = name;
    REQUIRE(::write(fd_, text.data(), text.size()) == static_cast<ssize_t>(text.size()));
  }
  ~TempFile() {
    ::close(fd_);
    std::remove(path_.c_str());
  }
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
  std::string path_;
};

struct Expected {
  std::string text;
  int number;
  bool terminated;
};

// What the source read before it streamed: the text cut at `end`, split at every "\n", "\r" before
// it dropped, the last line terminated only if the file has a newline after `end`.
std::vector<Expected> reference_lines(const std::string& text, std::size_t begin, std::size_t end, int first) {
  std::vector<Expected> lines;
  std::size_t pos = begin;
  int number = first;
  while (pos < end) {
    std::size_t nl = text.find('\n', pos);
    Expected e;
    e.number = number++;
    if (nl == std::string::npos || nl >= end) {
      e.text = text.substr(pos, end - pos);
      e.terminated = text.size() > end;
      pos = end;
    } else {
      e.text = text.substr(pos, nl - pos);
      e.terminated = true;
      pos = nl + 1;
    }
    if (!e.text.empty() && e.text.back() == '\r') e.text.pop_back();
    lines.push_back(e);
  }
  return lines;
}

// Where the old reader ended the content: blank lines at the end dropped with their newlines.
std::size_t reference_end(const std::string& text) {
  std::size_t end = text.size();
  for (;;) {
    const std::size_t nl = end == 0 ? std::string::npos : text.rfind('\n', end - 1);
    const std::size_t start = nl == std::string::npos ? 0 : nl + 1;
    if (!csv::is_blank(std::string_view(text).substr(start, end - start))) return end;
    if (start == 0) return 0;
    end = nl;
  }
}

void check_stream(const std::string& text, std::size_t capacity) {
  TempFile file(text);
  const std::size_t end = reference_end(text);
  REQUIRE(csv::content_end(file.fd(), text.size()) == end);
  csv::LineStream stream(capacity);
  // From the start, and from the second line on (where the data rows begin after a header).
  for (std::size_t begin : {std::size_t{0}, std::min(end, text.find('\n') == std::string::npos ? end : text.find('\n') + 1)}) {
    const auto expected = reference_lines(text, begin, end, 1);
    stream.open(file.fd(), begin, end, text.size() > end, 1);
    csv::Line line;
    for (const auto& e : expected) {
      REQUIRE(stream.next(line));
      CHECK(std::string(line.text) == e.text);
      CHECK(line.number == e.number);
      CHECK(line.terminated == e.terminated);
    }
    CHECK(stream.done());
    CHECK_FALSE(stream.next(line));
  }
}

}  // namespace

// fixed cases: empty lines, CRLF, no final newline, blank tail, lines longer than the buffer
TEST_CASE("line stream splits as the whole text does") {
  std::vector<std::string> texts = {
      "",
      "\n",
      " \r\n\t\n",
      "a",
      "a\n",
      "a\nb",
      "a\r\nbb\r\n\r\nccc\r\n",
      "h\n\n\nx\n  \n\n",
      "header,1\nrow,2\nrow,3\r",
      "\n\nheader\nrow\n \n",
  };
  texts.push_back(std::string(1000, 'x').append("\nyyy\n").append(700, 'z'));
  for (const auto& text : texts)
    for (std::size_t capacity : {1, 2, 3, 7, 64, 4096}) {
      INFO("text of " << text.size() << " bytes, buffer " << capacity);
      check_stream(text, capacity);
    }
}

// random texts over the characters that matter, through small buffers that must grow
TEST_CASE("line stream matches on random texts") {
  std::mt19937 rng(12);
  const char alphabet[] = {'a', ',', ' ', '\r', '\n', '\n', '\t', '1'};
  for (int round = 0; round < 300; ++round) {
    std::string text(rng() % 200, ' ');
    for (char& c : text) c = alphabet[rng() % sizeof alphabet];
    INFO("round " << round);
    check_stream(text, 1 + rng() % 16);
  }
}

// a range ending before the file does keeps the last line's newline state from the file
TEST_CASE("line stream reports a file cut under it") {
  TempFile file("abc\ndef\n");
  csv::LineStream stream(2);
  stream.open(file.fd(), 0, 100, false, 1);  // a range beyond the file's end: it became shorter
  csv::Line line;
  REQUIRE(stream.next(line));
  CHECK(line.text == "abc");
  CHECK(stream.next(line));
  CHECK_THROWS_AS(stream.next(line), csv::ReadError);
}
