"""Scenes named by a study: a shipped scene's name (config/scenes/NAME.yaml) or a path to a scene
file, relative to the study file. The scene's text travels inside each task."""
import os

import yaml

from .schema import refuse

MAX_SCENE_BYTES = 1024 * 1024  # a scene file's size [bytes]; the shipped ones are ~5 kB


def shipped_scene_names(scene_dir):
    return sorted(f[:-5] for f in os.listdir(scene_dir) if f.endswith(".yaml"))


def resolve(study_path, parts, scene, scene_dir):
    """The scene file's path (absolute); a refusal naming the key when there is none."""
    candidates = [scene] if scene.endswith((".yaml", ".yml")) else []
    candidates.append(os.path.join(scene_dir, scene + ".yaml"))
    base = os.path.dirname(os.path.abspath(study_path))
    for candidate in candidates:
        for full in (candidate, os.path.join(base, candidate)):
            if os.path.isfile(full):
                return os.path.abspath(full)
    refuse(study_path, parts, "unknown scene '%s' (no %s)" % (scene, " or ".join(candidates)))


_texts = {}


def text_of(study_path, parts, scene_file):
    """The scene file's text (read once per file)."""
    if scene_file not in _texts:
        try:
            if os.path.getsize(scene_file) > MAX_SCENE_BYTES:
                refuse(study_path, parts, "scene file %s is larger than the cap of %d bytes"
                       % (os.path.basename(scene_file), MAX_SCENE_BYTES))
            with open(scene_file) as f:
                _texts[scene_file] = f.read()
        except (OSError, UnicodeDecodeError) as error:
            refuse(study_path, parts, "cannot read scene %s: %s" % (os.path.basename(scene_file),
                                                                     getattr(error, "strerror", None) or error))
    return _texts[scene_file]


def duration_of(study_path, parts, scene_file):
    """The scene's own duration [s] (its `duration` key)."""
    try:
        duration = float(yaml.safe_load(text_of(study_path, parts, scene_file))["duration"])
    except (KeyError, TypeError, ValueError, yaml.YAMLError):
        refuse(study_path, parts, "scene %s has no duration to end on" % os.path.basename(scene_file))
    if not duration > 0:
        refuse(study_path, parts, "scene %s has no duration > 0" % os.path.basename(scene_file))
    return duration
