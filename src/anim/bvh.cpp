// BVH motion files. drape parses BVH itself rather than through Assimp: Assimp's BVH importer
// refuses position channels on non-root joints (MakeHuman's sit pose has them on every joint), does
// not report the line of a malformed value, and turns the file into a scene graph whose Euler
// order, rest offsets and channel layout have to be recovered again for retargeting.
//
// Conventions (Biovision's, as CMU, MakeHuman and Blender read them): a joint's rotation is the
// product of its rotation channels in the order they are listed (Zrotation Yrotation Xrotation:
// R = Rz Ry Rx), in degrees, applied in the parent's frame after the joint's OFFSET. The root's
// position channels are its absolute position; another joint's position channels are added to its
// OFFSET (MakeHuman writes zeros there).
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "anim/motion_internal.hpp"
#include "drape/error.hpp"
#include "drape/motion.hpp"

namespace drape {
namespace {

constexpr size_t kMaxJoints = 4096;
constexpr size_t kMaxDepth = 512;
// No length or angle of a motion comes near it; beyond it a value would not stay finite as a float
// (a rotation's radians, an offset plus a position channel, a chain of 512 joints' offsets).
constexpr double kMaxMagnitude = 1e9;

struct Token {
  std::string_view text;
  size_t line = 0;
};

class Tokens {
 public:
  Tokens(std::string_view text, std::string source) : text_(text), source_(std::move(source)) {}

  // Next whitespace-separated token; an empty token at the end of the text.
  Token next() {
    skip_space();
    const size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    return {text_.substr(start, pos_ - start), line_};
  }
  Token peek() {
    const size_t pos = pos_, line = line_;
    Token t = next();
    pos_ = pos, line_ = line;
    return t;
  }
  // The rest of the current line (after "Frame Time:" etc. a value follows on the same line).
  bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }
  size_t line() const { return line_; }

  [[noreturn]] void fail(size_t line, const std::string& what) const {
    throw InputError(source_, fmt::format("line {}: {}", line, what));
  }
  Token expect(std::string_view word) {
    Token t = next();
    if (t.text != word)
      fail(t.line, t.text.empty() ? fmt::format("expected '{}', found the end of the file", word)
                                  : fmt::format("expected '{}', found '{}'", word, motion_detail::printable(t.text)));
    return t;
  }
  double number(std::string_view what) {
    Token t = next();
    if (t.text.empty()) fail(t.line, fmt::format("expected {}, found the end of the file", what));
    double value = 0;
    std::string_view s = t.text;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    // from_chars does not take ".5" with a leading '-'? It does; it refuses a leading '+', handled above.
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec != std::errc() || end != s.data() + s.size())
      fail(t.line, fmt::format("{} '{}' is not a number", what, motion_detail::printable(t.text)));
    if (!std::isfinite(value)) fail(t.line, fmt::format("{} '{}' is not finite", what, motion_detail::printable(t.text)));
    return value;
  }
  // A length or an angle: a number within ±kMaxMagnitude.
  double value(std::string_view what) {
    const size_t line = peek().line;
    const double v = number(what);
    if (std::abs(v) > kMaxMagnitude) fail(line, fmt::format("{} {:g} is out of range (at most {:g} either way)", what, v, kMaxMagnitude));
    return v;
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  std::string_view text_;
  std::string source_;
  size_t pos_ = 0;
  size_t line_ = 1;
};

enum class Channel : uint8_t { Xpos, Ypos, Zpos, Xrot, Yrot, Zrot };

struct BvhJoint {
  std::string name;
  int parent = -1;
  Vec3f offset = Vec3f::Zero();
  std::vector<Channel> channels;
  size_t first_channel = 0;
  size_t line = 0;
};

Channel parse_channel(Tokens& tokens, const Token& t) {
  static constexpr std::pair<std::string_view, Channel> kNames[] = {
      {"Xposition", Channel::Xpos}, {"Yposition", Channel::Ypos}, {"Zposition", Channel::Zpos},
      {"Xrotation", Channel::Xrot}, {"Yrotation", Channel::Yrot}, {"Zrotation", Channel::Zrot}};
  for (const auto& [name, channel] : kNames)
    if (t.text == name) return channel;
  tokens.fail(t.line, fmt::format("unknown channel '{}' (Xposition ... Zrotation)", motion_detail::printable(t.text)));
}

}  // namespace

Motion parse_bvh(std::string_view text, const std::string& source, const MotionOptions& options) {
  Tokens tokens(text, source);
  if (text.empty()) throw InputError(source, "empty file (not BVH)");
  tokens.expect("HIERARCHY");

  // The hierarchy, read without recursion (a deeply nested file must not exhaust the stack).
  std::vector<BvhJoint> joints;
  std::vector<int> stack;  // open joints (-2: an End Site)
  size_t channel_count = 0;
  bool seen_root = false;
  while (true) {
    const Token t = tokens.next();
    if (t.text.empty()) tokens.fail(t.line, "the file ends inside the hierarchy (no MOTION section)");
    if (t.text == "ROOT" || t.text == "JOINT") {
      if (t.text == "ROOT" && !stack.empty()) tokens.fail(t.line, "ROOT inside another joint");
      if (t.text == "JOINT" && stack.empty()) tokens.fail(t.line, "JOINT outside a ROOT");
      if (t.text == "ROOT" && seen_root)
        tokens.fail(t.line, "a second ROOT (drape reads one skeleton per file)");
      if (!stack.empty() && stack.back() == -2) tokens.fail(t.line, "a JOINT inside an End Site");
      seen_root = true;
      const Token name = tokens.next();
      if (name.text.empty() || name.text == "{") tokens.fail(name.line, "a joint without a name");
      if (joints.size() >= kMaxJoints) tokens.fail(t.line, fmt::format("more than {} joints", kMaxJoints));
      if (stack.size() >= kMaxDepth) tokens.fail(t.line, fmt::format("joints nested deeper than {}", kMaxDepth));
      BvhJoint j;
      j.name = std::string(name.text);
      for (const BvhJoint& other : joints)
        if (other.name == j.name) tokens.fail(name.line, fmt::format("joint '{}' appears twice", motion_detail::printable(j.name)));
      j.parent = stack.empty() ? -1 : stack.back();
      j.line = t.line;
      tokens.expect("{");
      tokens.expect("OFFSET");
      for (int k = 0; k < 3; ++k) j.offset[k] = static_cast<float>(tokens.value(fmt::format("joint '{}' OFFSET", motion_detail::printable(j.name))));
      const Token ch = tokens.next();
      if (ch.text != "CHANNELS")
        tokens.fail(ch.line, fmt::format("joint '{}': expected CHANNELS after its OFFSET, found '{}'", motion_detail::printable(j.name),
                                         motion_detail::printable(ch.text)));
      const double n = tokens.number(fmt::format("joint '{}' channel count", motion_detail::printable(j.name)));
      if (n != 3 && n != 6 && n != 0)
        tokens.fail(ch.line, fmt::format("joint '{}' has {} channels (3 or 6)", motion_detail::printable(j.name), n));
      for (int k = 0; k < static_cast<int>(n); ++k) {
        const Token c = tokens.next();
        const Channel channel = parse_channel(tokens, c);
        for (Channel other : j.channels)
          if (other == channel) tokens.fail(c.line, fmt::format("joint '{}' lists channel '{}' twice", motion_detail::printable(j.name), c.text));
        j.channels.push_back(channel);
      }
      j.first_channel = channel_count;
      channel_count += j.channels.size();
      joints.push_back(std::move(j));
      stack.push_back(static_cast<int>(joints.size()) - 1);
    } else if (t.text == "End") {
      tokens.expect("Site");
      if (stack.empty() || stack.back() == -2) tokens.fail(t.line, "an End Site outside a joint");
      tokens.expect("{");
      tokens.expect("OFFSET");
      for (int k = 0; k < 3; ++k) tokens.value("End Site OFFSET");
      stack.push_back(-2);
    } else if (t.text == "}") {
      if (stack.empty()) tokens.fail(t.line, "a '}' with no joint open");
      stack.pop_back();
    } else if (t.text == "MOTION") {
      if (!stack.empty()) tokens.fail(t.line, fmt::format("MOTION before joint '{}' was closed with '}}'",
                                                          stack.back() >= 0 ? joints[static_cast<size_t>(stack.back())].name : "End Site"));
      break;
    } else {
      tokens.fail(t.line, fmt::format("unexpected '{}' in the hierarchy (ROOT, JOINT, End Site, OFFSET, CHANNELS)",
                                      motion_detail::printable(t.text)));
    }
  }
  if (joints.empty()) throw InputError(source, "the hierarchy has no joints");
  if (channel_count == 0) throw InputError(source, "no joint has channels: there is no motion");

  // MOTION: "Frames: N", "Frame Time: s", then N lines of channel_count values.
  const Token frames_word = tokens.expect("Frames:");
  const double frames = tokens.number("the frame count");
  if (frames < 1 || frames != std::floor(frames)) tokens.fail(frames_word.line, fmt::format("frame count {} is not a positive whole number", frames));
  tokens.expect("Frame");
  const Token time_word = tokens.expect("Time:");
  const double frame_time = tokens.number("the frame time");
  if (!(frame_time > 0 && frame_time <= 10)) tokens.fail(time_word.line, fmt::format("frame time {} s is not in (0, 10]", frame_time));
  // Every value takes at least two bytes ("0 "): a frame count the text cannot hold is refused
  // before anything is allocated for it.
  const double values = frames * static_cast<double>(channel_count);
  if (values > static_cast<double>(text.size()) / 2 + 1)
    tokens.fail(frames_word.line, fmt::format("{} frames of {} channels do not fit in the file's {} bytes", frames, channel_count, text.size()));

  Motion m;
  m.source = source;
  m.format = "bvh";
  m.frame_time = frame_time;
  m.frame_count = static_cast<size_t>(frames);
  const size_t nj = joints.size();
  for (const BvhJoint& j : joints) {
    m.names.push_back(j.name);
    m.parent.push_back(j.parent);
    m.rest_offset.push_back(j.offset);
    m.rest_rotation.push_back(Quatf::Identity());
  }
  m.rotation.resize(m.frame_count * nj);
  m.translation.resize(m.frame_count * nj);
  std::vector<double> row(channel_count);
  for (size_t f = 0; f < m.frame_count; ++f) {
    for (size_t c = 0; c < channel_count; ++c) {
      if (tokens.at_end())
        tokens.fail(tokens.line(), fmt::format("frame {} ends after {} of its {} values ({} frames declared)", f, c, channel_count, m.frame_count));
      row[c] = tokens.value(fmt::format("frame {} value {}", f, c + 1));
    }
    for (size_t j = 0; j < nj; ++j) {
      const BvhJoint& joint = joints[j];
      Quatf q = Quatf::Identity();
      Vec3f t = joint.parent < 0 ? Vec3f::Zero() : joint.offset;
      bool has_position = false;
      for (size_t k = 0; k < joint.channels.size(); ++k) {
        const double v = row[joint.first_channel + k];
        switch (joint.channels[k]) {
          case Channel::Xpos: t.x() += static_cast<float>(v), has_position = true; break;
          case Channel::Ypos: t.y() += static_cast<float>(v), has_position = true; break;
          case Channel::Zpos: t.z() += static_cast<float>(v), has_position = true; break;
          case Channel::Xrot: q = q * Quatf(Eigen::AngleAxisf(static_cast<float>(v * M_PI / 180), Vec3f::UnitX())); break;
          case Channel::Yrot: q = q * Quatf(Eigen::AngleAxisf(static_cast<float>(v * M_PI / 180), Vec3f::UnitY())); break;
          case Channel::Zrot: q = q * Quatf(Eigen::AngleAxisf(static_cast<float>(v * M_PI / 180), Vec3f::UnitZ())); break;
        }
      }
      if (joint.parent < 0 && !has_position) t = joint.offset;
      m.rotation[f * nj + j] = q.normalized();
      m.translation[f * nj + j] = t;
    }
  }
  if (!tokens.at_end()) {
    const Token extra = tokens.next();
    tokens.fail(extra.line, fmt::format("more values than {} frames of {} channels ('{}')", m.frame_count, channel_count,
                                        motion_detail::printable(extra.text)));
  }
  motion_detail::convert_axes(m, options);
  return m;
}

}  // namespace drape
