// scene_from and scene_document (scene_source.h): Python values ↔ a scene's YAML document.
#include "scene_source.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace birkhoff_cart {
namespace python {
namespace {

namespace py = pybind11;

std::string join_key(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

/// Where to_yaml is in a Python value: the scene source (for SceneError), the maps and lists from
/// the root to here (a cycle returns to one of them; their count is the depth), and the bytes of
/// text so far (a lower bound of the document's size: each node's scalar and one byte).
struct Walk {
  std::string source;
  std::vector<std::pair<PyObject*, std::string>> open;  ///< each container and its dotted key
  std::size_t text_bytes = 0;
};

/// Counts `bytes` more of the document at `key`: beyond kMaxSceneBytes, a SceneError there (before
/// the document is written out, which for 10 MB of text would take seconds).
void count_text(Walk& walk, const std::string& key, std::size_t bytes) {
  walk.text_bytes += bytes + 1;
  if (walk.text_bytes > kMaxSceneBytes) {
    throw SceneError(walk.source, key,
                     "takes the document beyond the cap of " + std::to_string(kMaxSceneBytes) + " bytes of a scene");
  }
}

/// The UTF-8 bytes of a str, or a SceneError naming `key` for a str that has none (lone surrogates).
std::string utf8_text(const py::handle& text, const std::string& key, const Walk& walk, const char* what) {
  Py_ssize_t size = 0;
  const char* bytes = PyUnicode_AsUTF8AndSize(text.ptr(), &size);
  if (bytes == nullptr) {
    PyErr_Clear();
    throw SceneError(walk.source, key, std::string(what) + " " + std::string(py::repr(text)) + " is not UTF-8 text");
  }
  return std::string(bytes, static_cast<std::size_t>(size));
}

/// A Python value as a YAML node; `key` (dotted, as in SceneError) names it in an error: TypeError
/// for a value no scene holds, SceneError for a map or list that holds itself or nests deeper than
/// kMaxSceneDepth, and for text that is not UTF-8.
YAML::Node to_yaml(const py::handle& value, const std::string& key, Walk& walk) {
  const std::string shown = key.empty() ? "(document)" : key;
  if (value.is_none()) return YAML::Node(YAML::NodeType::Null);
  if (py::isinstance<py::bool_>(value)) return YAML::Node(value.cast<bool>() ? "true" : "false");
  if (py::isinstance<py::str>(value)) {
    std::string text = utf8_text(value, shown, walk, "the value");
    count_text(walk, shown, text.size());
    return YAML::Node(text);
  }
  count_text(walk, shown, 0);
  const bool is_map = py::isinstance<py::dict>(value);
  if (is_map || py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    for (const auto& [container, container_key] : walk.open) {
      if (container == value.ptr()) {
        throw SceneError(walk.source, shown,
                         "holds the map or list at '" + (container_key.empty() ? "(document)" : container_key) +
                             "' that holds it: a cycle, which no scene file can hold");
      }
    }
    if (walk.open.size() >= static_cast<std::size_t>(kMaxSceneDepth)) {
      throw SceneError(walk.source, shown,
                       "nests maps and lists deeper than the cap of " + std::to_string(kMaxSceneDepth) + " levels");
    }
    walk.open.emplace_back(value.ptr(), key);
    YAML::Node node(is_map ? YAML::NodeType::Map : YAML::NodeType::Sequence);
    if (is_map) {
      for (const auto& [name, child] : value.cast<py::dict>()) {
        if (!py::isinstance<py::str>(name)) {
          throw py::type_error("scene key '" + shown + "': the names of a map must be str, got " +
                               std::string(py::repr(name)));
        }
        const std::string child_key = utf8_text(name, join_key(key, std::string(py::repr(name))), walk, "the name");
        count_text(walk, join_key(key, child_key), child_key.size());
        node[child_key] = to_yaml(child, join_key(key, child_key), walk);
      }
    } else {
      std::size_t index = 0;
      for (const py::handle item : value) node.push_back(to_yaml(item, key + "[" + std::to_string(index++) + "]", walk));
    }
    walk.open.pop_back();
    return node;
  }
  if (PyIndex_Check(value.ptr()) && !PyFloat_Check(value.ptr())) {  // int, numpy integers
    return YAML::Node(std::string(py::str(py::int_(py::reinterpret_borrow<py::object>(value)))));
  }
  if (PyFloat_Check(value.ptr()) || py::hasattr(value, "__float__")) {  // float, numpy floats
    const double number = py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
    if (std::isnan(number)) return YAML::Node(".nan");
    if (std::isinf(number)) return YAML::Node(number > 0 ? ".inf" : "-.inf");
    std::ostringstream text;  // 17 significant digits: the same double back
    text.precision(17);
    text << number;
    return YAML::Node(text.str());
  }
  throw py::type_error("scene key '" + shown + "': a scene holds maps, lists, str, bool, int and float, got " +
                       std::string(py::str(value.get_type().attr("__name__"))));
}

YAML::Node document_of(const py::handle& value, const std::string& source) {
  Walk walk{source, {}};
  return to_yaml(value, "", walk);
}

/// The bytes of a path given as str, bytes or os.PathLike (os.fsencode): the file system's own name,
/// whatever its encoding. Messages show it decoded (undecodable bytes as \xNN).
std::string path_bytes(const py::object& path) {
  return py::module_::import("os").attr("fsencode")(path).cast<std::string>();
}

/// Python values of a YAML node: maps as dicts, sequences as lists, scalars as bool, int, float or
/// str (in that order of trial, as YAML's core schema reads them).
py::object to_python(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      py::dict map;
      for (const auto& entry : node) map[py::str(entry.first.Scalar())] = to_python(entry.second);
      return std::move(map);
    }
    case YAML::NodeType::Sequence: {
      py::list sequence;
      for (const auto& item : node) sequence.append(to_python(item));
      return std::move(sequence);
    }
    case YAML::NodeType::Scalar: {
      if (node.Tag() == "!") return py::str(node.Scalar());  // quoted: a string whatever it reads like
      bool flag = false;
      if (YAML::convert<bool>::decode(node, flag)) return py::bool_(flag);
      long long whole = 0;
      if (YAML::convert<long long>::decode(node, whole)) return py::int_(whole);
      double number = 0.0;
      if (YAML::convert<double>::decode(node, number)) return py::float_(number);
      return py::str(node.Scalar());
    }
    default:
      return py::none();
  }
}

/// `overrides` merged into `document`: maps key by key, a null removes the key, anything else
/// replaces the value.
void merge(YAML::Node document, const YAML::Node& overrides) {
  for (const auto& entry : overrides) {
    const std::string key = entry.first.Scalar();
    const YAML::Node& value = entry.second;
    if (value.IsNull()) {
      document.remove(key);
    } else if (value.IsMap() && document[key] && document[key].IsMap()) {
      merge(document[key], value);
    } else {
      document[key] = value;
    }
  }
}

std::string emit(const YAML::Node& document) {
  YAML::Emitter out;
  out << document;
  return out.c_str();
}

}  // namespace

Scene scene_from(const py::object& source, const py::object& overrides) {
  const bool has_overrides = !overrides.is_none();
  if (has_overrides && !py::isinstance<py::dict>(overrides)) throw py::type_error("overrides must be a dict (or None)");
  if (py::isinstance<py::dict>(source)) {
    YAML::Node document = document_of(source, "<dict>");
    if (has_overrides) merge(document, document_of(overrides, "<dict>"));
    Scene scene = load_scene_text(emit(document), "<dict>");
    scene.name = "dict";
    return scene;
  }
  const std::string path = path_bytes(source);
  const std::string text = read_scene_file(path);  // within the size cap, as every face reads it
  Scene scene = load_scene_text(text, path);     // the file as the CLI reads it, its own errors named first
  if (!has_overrides) return scene;
  const std::string name = scene.name;
  const std::string with_overrides = path + " with overrides";
  YAML::Node document = YAML::Load(text);
  merge(document, document_of(overrides, with_overrides));
  scene = load_scene_text(emit(document), with_overrides);
  scene.name = name;
  scene.source_path = path;
  return scene;
}

py::object scene_document(const py::object& path) {
  const std::string file = path_bytes(path);
  const std::string text = read_scene_file(file);
  load_scene_text(text, file);  // a usable scene file, or the SceneError that names what is wrong
  return to_python(YAML::Load(text));
}

}  // namespace python
}  // namespace birkhoff_cart
