// Purpose: the streams of a sink that records one run for plots (sink.track, sink.scene): one per input port and item kind it takes, named <kind>:<node>, found per item in constant time.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/items.hpp>

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace trackflow::recording {

// One recorded stream: an input port and one item kind. A field record (run_result_codec.hpp)
// when Point is trivially copyable.
template <class Point>
struct Stream {
  ItemKind kind;
  std::vector<Point> points;
  template <class Self, class F>
  static void fields(Self& s, F&& f) {
    f(s.kind, s.points);
  }
};

// The streams laid out from a sink's inputs: for each port, one per kind of `kinds` that the
// port delivers, in port order and then in the order of `kinds`.
template <class Point>
class PortStreams {
 public:
  void lay_out(const std::vector<InputInfo>& inputs, std::span<const ItemKind> kinds) {
    kinds_ = kinds.size();
    index_.assign(inputs.size() * kinds_, -1);
    streams_.clear();
    names_.clear();
    for (std::size_t port = 0; port < inputs.size(); ++port)
      for (std::size_t k = 0; k < kinds_; ++k)
        if (inputs[port].kinds & mask(kinds[k])) {
          index_[port * kinds_ + k] = static_cast<int>(streams_.size());
          streams_.push_back({kinds[k], {}});
          names_.push_back(std::string(to_string(kinds[k])) + ":" + inputs[port].node);
        }
  }

  // The stream of `port` for kinds[slot], or nullptr when that port delivers no such items.
  Stream<Point>* find(int port, std::size_t slot) {
    if (port < 0 || static_cast<std::size_t>(port) * kinds_ + slot >= index_.size()) return nullptr;
    const int i = index_[static_cast<std::size_t>(port) * kinds_ + slot];
    return i < 0 ? nullptr : &streams_[static_cast<std::size_t>(i)];
  }

  std::vector<Stream<Point>>& streams() { return streams_; }
  const std::vector<Stream<Point>>& streams() const { return streams_; }
  const std::vector<std::string>& names() const { return names_; }

 private:
  std::size_t kinds_ = 0;
  std::vector<int> index_;  // (port, slot) -> stream
  std::vector<Stream<Point>> streams_;
  std::vector<std::string> names_;
};

}  // namespace trackflow::recording
