// A scene's text read and walked within bounds before any YAML tree is built (docs/scenes.md
// "Limits"): read_scene_file (scene.h) reads at most kMaxSceneBytes of a file, a pipe or a device;
// check_scene_structure (scene_reader.h) walks the parser's events once, refusing nesting deeper
// than kMaxSceneDepth and text that is not UTF-8, each by the dotted key where it happens.
#include <sys/stat.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "birkhoff_cart/core/scene/scene.h"
#include "scene_reader.h"

namespace birkhoff_cart {
namespace scene_detail {
namespace {

/// The length of the UTF-8 sequence that starts `text` at `at`, or 0 when it is not one (overlong
/// forms, surrogates and code points beyond U+10FFFF included).
std::size_t utf8_sequence_length(const std::string& text, std::size_t at) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[at + k]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return 1;
  std::size_t length = 0;
  unsigned long code = 0;
  if ((lead & 0xE0) == 0xC0) {
    length = 2, code = lead & 0x1F;
  } else if ((lead & 0xF0) == 0xE0) {
    length = 3, code = lead & 0x0F;
  } else if ((lead & 0xF8) == 0xF0) {
    length = 4, code = lead & 0x07;
  } else {
    return 0;
  }
  if (at + length > text.size()) return 0;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(k) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(k) & 0x3F);
  }
  const unsigned long smallest[] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < smallest[length] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  return length;
}

/// The offset of the first byte of `text` that is not UTF-8, or npos.
std::size_t first_non_utf8(const std::string& text) {
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t length = utf8_sequence_length(text, at);
    if (length == 0) return at;
    at += length;
  }
  return std::string::npos;
}

/// `text` with each byte that is not UTF-8 written as \xNN: printable in a message.
std::string escaped(const std::string& text) {
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t length = utf8_sequence_length(text, at);
    if (length == 0) {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned char>(text[at]));
      out += hex;
      ++at;
    } else {
      out.append(text, at, length);
      at += length;
    }
  }
  return out;
}

/// Follows the parser's events with the dotted key of each node; refuses the first map or list
/// deeper than kMaxSceneDepth and the first key or value that is not UTF-8.
class StructureCheck : public YAML::EventHandler {
 public:
  explicit StructureCheck(const SceneReader& reader) : reader_(reader) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override { node_done(); }
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override { node_done(); }
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string& value) override {
    const bool is_key = !open_.empty() && open_.back().is_map && open_.back().expects_key;
    if (is_key) {
      open_.back().key = value;
      open_.back().expects_key = false;
      if (first_non_utf8(value) != std::string::npos) reader_.fail(escaped(key_here()), "is not UTF-8 text");
      return;
    }
    const std::size_t bad = first_non_utf8(value);
    if (bad != std::string::npos) {
      char byte[5];
      std::snprintf(byte, sizeof byte, "0x%02x", static_cast<unsigned char>(value[bad]));
      reader_.fail(escaped(key_here()), std::string("has a value that is not UTF-8 text (byte ") + byte +
                                            " at offset " + std::to_string(bad) + " of the value)");
    }
    node_done();
  }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    open(false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    open(true);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Level {
    bool is_map = false;
    bool expects_key = true;  ///< a map's next node is a key
    std::string key;          ///< a map's current key
    std::size_t index = 0;    ///< a list's current item
  };

  /// The dotted key of the node being read ("(document)" at the root), as SceneReader names keys.
  std::string key_here() const {
    std::string key;
    for (const Level& level : open_) {
      if (level.is_map && !level.expects_key) {
        key = SceneReader::join(key, level.key);
      } else if (!level.is_map) {
        key += "[" + std::to_string(level.index) + "]";
      }
    }
    return key.empty() ? "(document)" : key;
  }

  void open(bool is_map) {
    if (open_.size() >= static_cast<std::size_t>(kMaxSceneDepth)) {
      reader_.fail(escaped(key_here()), "nests maps and lists deeper than the cap of " + std::to_string(kMaxSceneDepth) +
                                            " levels");
    }
    Level level;
    level.is_map = is_map;
    open_.push_back(level);
  }
  void close() {
    open_.pop_back();
    node_done();
  }
  /// A node ended: the enclosing map's next node is a key, the enclosing list's the next item.
  void node_done() {
    if (open_.empty()) return;
    Level& level = open_.back();
    if (level.is_map) {
      level.expects_key = !level.expects_key;
    } else {
      ++level.index;
    }
  }

  const SceneReader& reader_;
  std::vector<Level> open_;
};

}  // namespace

void check_scene_structure(const SceneReader& reader, const std::string& text) {
  if (text.size() > kMaxSceneBytes) {
    reader.fail("(document)", "is " + std::to_string(text.size()) + " bytes, beyond the cap of " +
                              std::to_string(kMaxSceneBytes) + " bytes of a scene");
  }
  std::istringstream stream(text);
  YAML::Parser parser(stream);
  StructureCheck check(reader);
  parser.HandleNextDocument(check);
}

}  // namespace scene_detail

std::string read_scene_file(const std::string& path) {
  const scene_detail::SceneReader reader(path);
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) {
    reader.fail("(file)", std::string("cannot be opened for reading (") + std::strerror(errno) + ")");
  }
  if (S_ISDIR(status.st_mode)) reader.fail("(file)", "is a directory, not a scene file");
  const std::string cap = std::to_string(kMaxSceneBytes) + " bytes of a scene";
  if (S_ISREG(status.st_mode) && static_cast<unsigned long long>(status.st_size) > kMaxSceneBytes) {
    reader.fail("(file)", "is " + std::to_string(status.st_size) + " bytes, beyond the cap of " + cap +
                              " (refused before reading)");
  }
  std::ifstream stream(path, std::ios::binary);
  if (!stream) reader.fail("(file)", "cannot be opened for reading");
  // At most one byte past the cap: a pipe or a device (/dev/stdin, /dev/zero) is read no further.
  std::string text(kMaxSceneBytes + 1, '\0');
  stream.read(&text[0], static_cast<std::streamsize>(text.size()));
  if (stream.bad()) reader.fail("(file)", "cannot be read");
  text.resize(static_cast<std::size_t>(stream.gcount()));
  if (text.size() > kMaxSceneBytes) reader.fail("(file)", "holds more than the cap of " + cap + " (read no further)");
  return text;
}

}  // namespace birkhoff_cart
