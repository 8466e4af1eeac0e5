// scene_from and scene_document (scene_source.h): Python values ↔ a scene's YAML document.
#include "scene_source.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

namespace birkhoff_cart {
namespace python {
namespace {

namespace py = pybind11;

std::string join_key(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

/// A Python value as a YAML node; `key` (dotted, as in SceneError) names it in a TypeError.
YAML::Node to_yaml(const py::handle& value, const std::string& key) {
  if (value.is_none()) return YAML::Node(YAML::NodeType::Null);
  if (py::isinstance<py::bool_>(value)) return YAML::Node(value.cast<bool>() ? "true" : "false");
  if (py::isinstance<py::str>(value)) return YAML::Node(value.cast<std::string>());
  if (py::isinstance<py::dict>(value)) {
    YAML::Node map(YAML::NodeType::Map);
    for (const auto& [name, child] : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(name)) {
        throw py::type_error("scene key '" + key + "': the names of a map must be str, got " +
                             std::string(py::repr(name)));
      }
      const std::string child_key = name.cast<std::string>();
      map[child_key] = to_yaml(child, join_key(key, child_key));
    }
    return map;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    YAML::Node sequence(YAML::NodeType::Sequence);
    std::size_t index = 0;
    for (const py::handle item : value) {
      sequence.push_back(to_yaml(item, key + "[" + std::to_string(index++) + "]"));
    }
    return sequence;
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
  throw py::type_error("scene key '" + key + "': a scene holds maps, lists, str, bool, int and float, got " +
                       std::string(py::str(value.get_type().attr("__name__"))));
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
  YAML::Node override_document;
  const bool has_overrides = !overrides.is_none();
  if (has_overrides) {
    if (!py::isinstance<py::dict>(overrides)) throw py::type_error("overrides must be a dict (or None)");
    override_document = to_yaml(overrides, "");
  }
  if (py::isinstance<py::dict>(source)) {
    YAML::Node document = to_yaml(source, "");
    if (has_overrides) merge(document, override_document);
    Scene scene = load_scene_text(emit(document), "<dict>");
    scene.name = "dict";
    return scene;
  }
  const std::string path = py::str(py::module_::import("os").attr("fspath")(source));
  Scene scene = load_scene(path);  // the file as the CLI reads it, its own errors named first
  if (!has_overrides) return scene;
  const std::string name = scene.name;
  YAML::Node document = YAML::LoadFile(path);
  merge(document, override_document);
  scene = load_scene_text(emit(document), path + " with overrides");
  scene.name = name;
  scene.source_path = path;
  return scene;
}

py::object scene_document(const std::string& path) {
  load_scene(path);  // a usable scene file, or the SceneError that names what is wrong
  return to_python(YAML::LoadFile(path));
}

}  // namespace python
}  // namespace birkhoff_cart
