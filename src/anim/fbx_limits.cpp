// What Assimp would make of an FBX file, bounded before Assimp reads it.
//
// Assimp 5.2's FBX importer trusts a file in ways that let a small file take gigabytes of memory,
// loop forever or overflow the stack:
//  - it splits rotation curves into keys under 180 degrees apart (FBXConverter's
//    GetRotationKeyframeList): a key of 1e11 degrees makes 600 million keys; two keys 180 degrees
//    or more apart and closer in time than one tick per 179 degrees, or values so large that a
//    float step of 179 degrees is lost, make it add the same key forever;
//  - its binary tokenizer and its parser recurse once per level of nesting;
//  - it keeps a token object (about 64 bytes) per value of an ASCII file and per property of a
//    binary one, and inflates each compressed array to the length the file declares (computed in 32
//    bits, so a large one wraps around).
// This pass walks the records of a binary file or the braces of an ASCII one without recursion,
// counts the tokens, checks each array's declared length against its compressed bytes, and reads
// every AnimationCurve's KeyTime and KeyValueFloat to bound the keys Assimp will add. It refuses
// what Assimp would choke on; everything else that is malformed is left to Assimp to report.
#include <fmt/format.h>
#include <zlib.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "anim/motion_internal.hpp"
#include "drape/error.hpp"

namespace drape {
namespace {

constexpr size_t kMaxDepth = 64;           // FBX files nest a few levels
constexpr size_t kMaxTokens = 16'000'000;  // about 1 GB of Assimp's tokens
constexpr uint64_t kMaxInflatedBytes = 1ull << 30;
constexpr double kMaxAddedKeys = 2'000'000;  // keys Assimp adds to split rotation curves
constexpr double kMaxKeyValue = 1e6;         // degrees: a float step of 179 still counts
constexpr double kDeflateMaxRatio = 1032;    // the most deflate can shrink data

// One AnimationCurve's keys, checked when the curve ends.
struct Curve {
  std::string id;
  std::vector<int64_t> times;  // FBX ticks (1/46186158000 s)
  std::vector<double> values;
};

class Limits {
 public:
  explicit Limits(const std::string& source) : source_(source) {}

  [[noreturn]] void fail(const std::string& what) const { throw InputError(source_, what); }

  void count_tokens(uint64_t n) {
    tokens_ += n;
    if (tokens_ > kMaxTokens)
      fail(fmt::format("more than {} values and properties: larger than drape reads", kMaxTokens));
  }
  void depth(size_t d) const {
    if (d > kMaxDepth) fail(fmt::format("nested deeper than {} levels", kMaxDepth));
  }
  void inflate(uint64_t bytes, uint64_t compressed) {
    inflated_ += bytes;
    if (static_cast<double>(bytes) > kDeflateMaxRatio * static_cast<double>(compressed) + 64)
      fail(fmt::format(
          "a compressed array of {} bytes says it holds {} bytes (deflate shrinks at most {}-fold)",
          compressed, bytes, kDeflateMaxRatio));
    if (inflated_ > kMaxInflatedBytes)
      fail(fmt::format("its compressed arrays hold more than {} MiB", kMaxInflatedBytes >> 20));
  }

  // Assimp walks from each key of a rotation curve to the next in steps of floor(dt / dv * 179)
  // ticks while the values are 180 degrees or more apart. Which curves turn joints only the file's
  // connections say, so every curve is held to it; values that never jump so far (a timecode, a
  // morph weight, NaN) are let through, whatever their size.
  void check(const Curve& c) {
    const size_t n = std::min(c.times.size(), c.values.size());
    for (size_t k = 1; k < n; ++k) {
      const float a = static_cast<float>(c.values[k - 1]), b = static_cast<float>(c.values[k]);
      const double dv = std::abs(static_cast<double>(b) - static_cast<double>(a));
      if (!(dv >= 180)) continue;
      if (!(std::max(std::abs(a), std::abs(b)) <= kMaxKeyValue))
        fail(fmt::format(
            "AnimationCurve {}: keys {} and {} jump from {:g} to {:g} (beyond ±{:g}, where a float step of "
            "179 degrees is lost, Assimp would split the turn without end)",
            c.id, k - 1, k, a, b, kMaxKeyValue));
      const double dt = static_cast<double>(c.times[k]) - static_cast<double>(c.times[k - 1]);
      if (dt / dv * 179 < 1)
        fail(fmt::format(
            "AnimationCurve {}: keys {} and {} are {:g} apart in {:g} s: an Euler angle cannot turn so fast",
            c.id, k - 1, k, dv, dt / 46186158000.0));
      added_keys_ += dv / 179 + 1;
      if (added_keys_ > kMaxAddedKeys)
        fail(fmt::format(
            "its rotation curves turn by so much between keys that Assimp would add more than {:g} keys",
            kMaxAddedKeys));
    }
  }

 private:
  const std::string& source_;
  uint64_t tokens_ = 0;
  uint64_t inflated_ = 0;
  double added_keys_ = 0;
};

// ---- Binary FBX: records of (end offset, property count, property bytes, name, properties, children,
// a null record), offsets 64-bit from version 7500 on.

class BinaryWalk {
 public:
  BinaryWalk(std::span<const unsigned char> b, Limits& limits) : b_(b), limits_(limits) {}

  void run() {
    if (b_.size() < 27) limits_.fail("not a readable FBX file (shorter than a binary FBX header)");
    const uint32_t version = static_cast<uint32_t>(read(23, 4));
    const uint64_t word = version >= 7500 ? 8 : 4, null_record = 3 * word + 1;
    struct Open {
      uint64_t end;
      bool curve;
    };
    std::vector<Open> open;
    Curve curve;
    uint64_t pos = 27;
    while (true) {
      while (!open.empty() && pos + null_record >= open.back().end) {
        if (pos + null_record != open.back().end) fail(pos, "a record's children overrun it");
        for (uint64_t i = 0; i < null_record; ++i)
          if (b_[pos + i] != 0) fail(pos, "a record's children do not end with a null record");
        if (open.back().curve) limits_.check(curve);
        pos = open.back().end;
        open.pop_back();
      }
      if (pos + word > b_.size()) {
        if (open.empty()) break;
        fail(pos, "the file ends inside a record");
      }
      const uint64_t end = read(pos, word);
      if (end == 0) {
        if (open.empty()) break;  // the footer
        fail(pos, "a null record before a record's end");
      }
      if (end > b_.size() || end <= pos || (!open.empty() && end > open.back().end - null_record))
        fail(pos, fmt::format("a record ends at byte {}, outside its parent or the file", end));
      const uint64_t count = read(pos + word, word), length = read(pos + 2 * word, word);
      const uint64_t name_at = pos + 3 * word;
      if (name_at + 1 > end) fail(pos, "a record shorter than its header");
      const uint64_t name_length = b_[name_at];
      if (name_at + 1 + name_length > end) fail(pos, "a record's name runs past its end");
      const std::string_view name(reinterpret_cast<const char*>(b_.data() + name_at + 1), name_length);
      const uint64_t props = name_at + 1 + name_length;
      if (length > end - props) fail(pos, "a record's properties run past its end");
      if (count > length) fail(pos, "a record says it has more properties than bytes");
      limits_.count_tokens(1 + 2 * count + 2);
      const bool parent_curve = !open.empty() && open.back().curve;
      const bool curve_record = name == "AnimationCurve";
      if (curve_record) curve = Curve{};
      std::vector<int64_t>* times = parent_curve && name == "KeyTime" ? &curve.times : nullptr;
      std::vector<double>* values = parent_curve && name == "KeyValueFloat" ? &curve.values : nullptr;
      uint64_t at = props;
      for (uint64_t i = 0; i < count; ++i)
        at = property(at, props + length, i == 0 && curve_record ? &curve.id : nullptr,
                      i == 0 ? times : nullptr, i == 0 ? values : nullptr);
      if (at != props + length) fail(pos, "a record's properties do not fill their length");
      if (at < end) {
        if (end - at < null_record) fail(pos, "a record's children do not end with a null record");
        open.push_back({end, curve_record});
        limits_.depth(open.size());
      } else if (curve_record) {
        limits_.check(curve);
      }
      pos = at;
    }
  }

 private:
  [[noreturn]] void fail(uint64_t at, const std::string& what) const {
    limits_.fail(fmt::format("not a readable FBX file (byte {}: {})", at, what));
  }

  uint64_t read(uint64_t at, uint64_t bytes) const {
    if (at + bytes > b_.size()) fail(at, "the file ends inside a record");
    uint64_t v = 0;
    for (uint64_t i = 0; i < bytes; ++i) v |= static_cast<uint64_t>(b_[at + i]) << (8 * i);
    return v;
  }

  // One property at `at` (within `end`); the curve's id, times or values when asked. Returns its end.
  uint64_t property(uint64_t at, uint64_t end, std::string* id, std::vector<int64_t>* times,
                    std::vector<double>* values) {
    if (at >= end) fail(at, "fewer properties than the record says");
    const char type = static_cast<char>(b_[at++]);
    uint64_t size = 0;
    switch (type) {
      case 'C':
        size = 1;
        break;
      case 'Y':
        size = 2;
        break;
      case 'I':
      case 'F':
        size = 4;
        break;
      case 'D':
        size = 8;
        break;
      case 'L':
        if (id && at + 8 <= end) *id = std::to_string(static_cast<int64_t>(read(at, 8)));
        size = 8;
        break;
      case 'S':
      case 'R':
        size = 4 + read(at, 4);
        break;
      case 'b':
        return end;  // Assimp takes the rest of the record's properties
      case 'f':
      case 'd':
      case 'l':
      case 'i':
      case 'c': {
        const uint64_t n = read(at, 4), encoding = read(at + 4, 4), compressed = read(at + 8, 4);
        const uint64_t stride = type == 'd' || type == 'l' ? 8 : type == 'c' ? 1 : 4;
        if (n * stride > 0xffffffffull)
          fail(at, fmt::format("an array of {} values of {} bytes (Assimp reads at most 4 GiB)", n, stride));
        if (encoding == 0 && n * stride != compressed) fail(at, "an array's length and bytes disagree");
        if (encoding == 1) limits_.inflate(n * stride, compressed);
        if (at + 12 + compressed > end) fail(at, "an array runs past its record");
        if (times || values) decode(type, n, encoding, at + 12, compressed, times, values);
        return at + 12 + compressed;
      }
      default:
        fail(at - 1,
             fmt::format("unknown property type {}", static_cast<int>(static_cast<unsigned char>(type))));
    }
    if (at + size > end) fail(at, "a property runs past its record");
    return at + size;
  }

  void decode(char type, uint64_t n, uint64_t encoding, uint64_t at, uint64_t compressed,
              std::vector<int64_t>* times, std::vector<double>* values) {
    const uint64_t stride = type == 'd' || type == 'l' ? 8 : type == 'c' ? 1 : 4;
    std::vector<unsigned char> raw;
    const unsigned char* data = b_.data() + at;
    if (encoding == 1) {
      raw.resize(n * stride);
      uLongf length = static_cast<uLongf>(raw.size());
      if (uncompress(raw.data(), &length, data, static_cast<uLong>(compressed)) != Z_OK ||
          length != raw.size())
        fail(at, "a compressed array does not inflate to its length");
      data = raw.data();
    } else if (encoding != 0) {
      return;  // Assimp refuses it
    }
    for (uint64_t i = 0; i < n; ++i) {
      const unsigned char* p = data + i * stride;
      if (times && type == 'l') {
        int64_t t;
        std::memcpy(&t, p, 8);
        times->push_back(t);
      } else if (values && type == 'f') {
        float v;
        std::memcpy(&v, p, 4);
        values->push_back(v);
      } else if (values && type == 'd') {
        double v;
        std::memcpy(&v, p, 8);
        values->push_back(v);
      }
    }
  }

  std::span<const unsigned char> b_;
  Limits& limits_;
};

// ---- ASCII FBX: `Key: values { children }`, ';' comments, "strings", arrays as `*N { a: v,v,... }`.

void walk_ascii(std::string_view s, Limits& limits) {
  size_t depth = 0, curve_depth = 0;  // curve_depth: the depth inside the open AnimationCurve, 0 none
  bool curve_next = false;            // an AnimationCurve key was read; its '{' comes
  Curve curve;
  std::vector<int64_t>* times = nullptr;  // the array being read
  std::vector<double>* values = nullptr;
  size_t array_depth = 0;
  size_t i = 0;
  auto is_separator = [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',' || c == '{' || c == '}' || c == ';' ||
           c == '"';
  };
  while (i < s.size()) {
    const char c = s[i];
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
      ++i;
    } else if (c == ';') {
      while (i < s.size() && s[i] != '\n') ++i;
    } else if (c == '"') {
      const size_t close = s.find('"', i + 1);
      i = close == std::string_view::npos ? s.size() : close + 1;
      limits.count_tokens(1);
    } else if (c == ',') {
      ++i;
      limits.count_tokens(1);
    } else if (c == '{') {
      ++i;
      limits.count_tokens(1);
      limits.depth(++depth);
      if (curve_next) curve_depth = depth, curve_next = false;
    } else if (c == '}') {
      ++i;
      limits.count_tokens(1);
      if (depth == 0) continue;  // unbalanced: Assimp says so
      if ((times || values) && depth == array_depth) times = nullptr, values = nullptr;
      if (depth == curve_depth) limits.check(curve), curve_depth = 0;
      --depth;
    } else {
      const size_t start = i;
      while (i < s.size() && !is_separator(s[i])) ++i;
      const std::string_view word = s.substr(start, i - start);
      limits.count_tokens(1);
      if (word.back() == ':' && word != "a:") {
        times = nullptr, values = nullptr;
        if (word == "AnimationCurve:") {
          curve = Curve{};
          curve_next = true;
        } else if (curve_depth && depth == curve_depth && (word == "KeyTime:" || word == "KeyValueFloat:")) {
          if (word == "KeyTime:")
            times = &curve.times;
          else
            values = &curve.values;
          array_depth = depth + 1;
        }
      } else if (curve_next && curve.id.empty()) {
        curve.id = std::string(word);
      } else if (times || values) {
        // Numbers as Assimp reads them: a leading '+' allowed, too large ones infinite.
        const char* begin = word.data() + (word.front() == '+' ? 1 : 0);
        const char* end = word.data() + word.size();
        if (times) {
          int64_t t = 0;
          if (std::from_chars(begin, end, t).ptr == end) times->push_back(t);
        } else {
          double v = 0;
          const auto [ptr, ec] = std::from_chars(begin, end, v);
          if (ptr == end) values->push_back(ec == std::errc::result_out_of_range ? HUGE_VAL : v);
        }
      }
    }
  }
}

}  // namespace

void motion_detail::check_fbx_limits(std::span<const unsigned char> bytes, const std::string& source) {
  Limits limits(source);
  if (bytes.size() >= 18 && std::memcmp(bytes.data(), "Kaydara FBX Binary", 18) == 0)
    BinaryWalk(bytes, limits).run();
  else
    walk_ascii(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), limits);
}

}  // namespace drape
