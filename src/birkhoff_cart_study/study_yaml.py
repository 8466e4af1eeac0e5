"""A study file's YAML, read within the caps of limits.py before any of it is built into values.

The file's size is checked before it is parsed; its nesting on the parser's event stream (no
recursion); its values, text and tags on the node graph, where a YAML alias is the same node met
again, so an alias bomb is refused by counting, without expanding it. Only plain values pass:
text, numbers, true/false, null, maps with text keys given once, and lists."""
import os

import yaml

from .limits import MAX_CHARACTERS, MAX_DEPTH, MAX_FILE_BYTES, MAX_TEXT, MAX_VALUES, StudyError, quoted, refusal

_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's parser when Debian's python3-yaml has it
_CORE = "tag:yaml.org,2002:"
PLAIN_TAGS = {_CORE + name for name in ("str", "int", "float", "bool", "null", "map", "seq", "merge")}
_TEXT_KEY = _CORE + "str"


def _refuse(path, parts, message):
    raise refusal(path, parts, message)


def _yaml_problem(path, error):
    mark = getattr(error, "problem_mark", None)
    where = " at line %d, column %d" % (mark.line + 1, mark.column + 1) if mark is not None else ""
    problem = getattr(error, "problem", None) or type(error).__name__
    return StudyError("study %s: not valid YAML%s: %s" % (path, where, problem[:120]))


def _check_nesting(path, text):
    """Refuses maps and lists nested deeper than MAX_DEPTH, from the parser's events."""
    depth = 0
    for event in yaml.parse(text, Loader=_Loader):
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            if depth > MAX_DEPTH:
                raise StudyError("study %s: maps and lists nested deeper than the cap of %d levels (line %d; "
                                 "limits.MAX_DEPTH)" % (path, MAX_DEPTH, event.start_mark.line + 1))
        elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1


def _check_nodes(path, root):
    """Walks the node graph as its values will be, each alias expanded, and stops at the first cap:
    MAX_VALUES values, MAX_CHARACTERS characters of text in all, MAX_TEXT in one; a tag other than
    the plain ones; a key that is not text or is given twice in one map."""
    values = characters = 0
    stack = [(root, ())]
    while stack:
        node, parts = stack.pop()
        values += 1
        if values > MAX_VALUES:
            _refuse(path, parts, "the file holds more than %d values once its YAML aliases are expanded "
                                 "(cap limits.MAX_VALUES)" % MAX_VALUES)
        if node.tag not in PLAIN_TAGS:
            if node.tag == _CORE + "timestamp":
                _refuse(path, parts, "a date or time is not a study value (quote it to make it text)")
            _refuse(path, parts, "YAML tag %s is not allowed (plain text, numbers, true/false, maps and "
                                 "lists only)" % quoted(node.tag.replace(_CORE, "!!"), 60))
        if isinstance(node, yaml.ScalarNode):
            if len(node.value) > MAX_TEXT:
                _refuse(path, parts, "a value of %d characters, more than the cap of %d (limits.MAX_TEXT)"
                        % (len(node.value), MAX_TEXT))
            characters += len(node.value)
            if characters > MAX_CHARACTERS:
                _refuse(path, parts, "the file holds more than %d characters of text once its YAML aliases are "
                                     "expanded (cap limits.MAX_CHARACTERS)" % MAX_CHARACTERS)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((item, parts + (i,)) for i, item in reversed(list(enumerate(node.value))))
        else:
            seen = set()
            children = []
            for key, value in node.value:
                if key.tag == _CORE + "merge":  # `<<: *anchor`: the anchored map's keys join this one
                    children.append((value, parts))
                    continue
                if not isinstance(key, yaml.ScalarNode) or key.tag != _TEXT_KEY:
                    _refuse(path, parts, "a key must be a name, got %s"
                            % (quoted(key.value) if isinstance(key, yaml.ScalarNode) else "a map or list"))
                if key.value in seen:
                    _refuse(path, parts + (key.value,), "given twice")
                seen.add(key.value)
                children.append((value, parts + (key.value,)))
            stack.extend(reversed(children))


def read_study_yaml(path):
    """The study file's document as plain Python values; StudyError naming the key (or the line)
    when the file is too large, not YAML, empty, or asks for more than the caps allow."""
    try:
        if not os.path.isfile(path):
            raise StudyError("study %s: no such file" % path)
        size = os.path.getsize(path)
        if size > MAX_FILE_BYTES:
            raise StudyError("study %s: %d bytes, more than the cap of %d (limits.MAX_FILE_BYTES)"
                             % (path, size, MAX_FILE_BYTES))
        with open(path, "rb") as f:
            data = f.read(MAX_FILE_BYTES + 1)
    except OSError as error:
        raise StudyError("study %s: cannot read it: %s" % (path, error.strerror))
    if len(data) > MAX_FILE_BYTES:
        raise StudyError("study %s: more than the cap of %d bytes (limits.MAX_FILE_BYTES)" % (path, MAX_FILE_BYTES))
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise StudyError("study %s: not UTF-8 text (byte %d)" % (path, error.start))
    try:
        _check_nesting(path, text)
        loader = _Loader(text)
        try:
            root = loader.get_single_node()
            if root is None:
                raise StudyError("study %s: the file is empty (a study is a map: name, kind, experiments, ...)" % path)
            _check_nodes(path, root)
            return loader.construct_document(root)
        finally:
            loader.dispose()
    except yaml.YAMLError as error:
        raise _yaml_problem(path, error)
    except (ValueError, OverflowError) as error:  # e.g. an integer of more digits than Python converts
        if isinstance(error, StudyError):
            raise
        raise StudyError("study %s: a value cannot be read: %s" % (path, str(error)[:120]))
