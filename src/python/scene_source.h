// A scene for the Python module from a file or a dict, with optional overrides: both become a YAML
// document that the core's scene reader validates (scene.h), so every error is the CLI's SceneError
// naming the key. docs/python.md, "Scenes".
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "birkhoff_cart/core/scene/scene.h"

namespace birkhoff_cart {
namespace python {

/// The scene at `source` (a path: str, bytes or os.PathLike, read within the core's size cap; or a
/// dict shaped like a scene file), with `overrides` (a dict, or None) merged into its document
/// first: a map merges key by key, None removes the key, any other value replaces it. Throws
/// SceneError naming the key (the source: the path, the path "with overrides", or "<dict>"), also
/// for a dict that holds itself, nests deeper than kMaxSceneDepth or holds text that is not UTF-8;
/// pybind11::type_error for a value YAML cannot hold, naming its key.
Scene scene_from(const pybind11::object& source, const pybind11::object& overrides);

/// The YAML document of the scene file at `path` (str, bytes or os.PathLike) as Python values (maps
/// as dicts, sequences as lists, scalars as bool, int, float or str): a shipped scene to edit and
/// pass back as a dict.
pybind11::object scene_document(const pybind11::object& path);

}  // namespace python
}  // namespace birkhoff_cart
