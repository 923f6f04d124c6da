#pragma once
// JsonLine: appends one JSON object to a string as its members are given, in order, with no
// document tree. `pmuctl decode --json` prints a line per frame; building an nlohmann object
// per line (a map, a string per key, a heap node per value) cost two thirds of its time.
//
// The bytes are exactly what nlohmann::ordered_json::dump(-1, ' ', false, replace) prints for
// the same members (the output is a contract, and scripts diff it): numbers are formatted by
// nlohmann's own shortest-round-trip routine, non-finite numbers are null, and a string
// needing more than plain ASCII (escapes, UTF-8, invalid bytes) is handed to nlohmann.
// Keys are our own names and are written as given.
//
// Lifetime: `out` must outlive the JsonLine, which appends to it until it is destroyed.
// Threads: one thread at a time, like the string.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace pmu::tools {

class JsonLine {
 public:
  explicit JsonLine(std::string& out) : out_(out) { put("{", 1); }
  ~JsonLine() { flush(); }
  JsonLine(const JsonLine&) = delete;
  JsonLine& operator=(const JsonLine&) = delete;

  JsonLine& number(std::string_view key, double v);
  JsonLine& integer(std::string_view key, std::int64_t v);
  JsonLine& boolean(std::string_view key, bool v);
  JsonLine& null(std::string_view key);
  JsonLine& string(std::string_view key, std::string_view v);
  // Opens a nested object as the value of `key`; members follow until end_object().
  JsonLine& begin_object(std::string_view key);
  JsonLine& end_object();
  // Closes the line: '}' and '\n'.
  void end();

 private:
  void key(std::string_view k);
  // Pieces gather here and reach `out_` in one append: a line is some forty small pieces,
  // and appending each to the string cost more than formatting them.
  void put(const char* p, std::size_t n);
  void put(std::string_view s) { put(s.data(), s.size()); }
  void flush();

  std::string& out_;
  bool first_ = true;
  std::size_t used_ = 0;
  char buf_[512];
};

}  // namespace pmu::tools
