"""Study files checked by a schema (JSON Schema, with Debian's python3-jsonschema): the parts every
kind's schema is made of, and the check that turns the first problem into one line naming the key.

Each study kind (kinds/*.py) builds its schema from these parts; the registry's names (integrators,
forms, step controls) come in as enums, so a typo is refused with the closest known name. Names
that reach file names (the study's name, labels) are limited to NAME_PATTERN; a number is a
finite number, never true/false; every list and text has a cap (limits.py)."""
import difflib
import math

import jsonschema

from .limits import MAX_LIST, MAX_TASKS, MAX_TEXT, quoted, refusal

NAME_PATTERN = "^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$"
NAME_TEXT = "a name of letters, digits, '_' and '-' (at most 64, the first a letter or digit)"
SCENE_PATTERN = "^[A-Za-z0-9_][A-Za-z0-9_./-]{0,254}$"
SCENE_TEXT = ("a shipped scene's name or the path of a scene file (letters, digits, '_', '-', '.' and '/', "
              "at most 255)")
TEXT_PATTERN = "^[^\\x00-\\x08\\x0b-\\x1f\\x7f]*$"


def _number(checker, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # an integer beyond the double range
        return False


def _integer(checker, value):
    return isinstance(value, int) and not isinstance(value, bool)


# A number is finite (YAML's .nan and .inf are refused) and never true/false; an integer is written
# without a point (3, not 3.0).
_TYPES = jsonschema.Draft7Validator.TYPE_CHECKER.redefine_many({"number": _number, "integer": _integer})
Validator = jsonschema.validators.extend(jsonschema.Draft7Validator, type_checker=_TYPES)

TYPE_TEXT = {"number": "a finite number", "integer": "a whole number", "string": "text", "boolean": "true or false",
             "object": "a map", "array": "a list", "null": "null"}


# --- parts -------------------------------------------------------------------------------------

def name(what="a name"):
    return {"type": "string", "pattern": NAME_PATTERN, "description": NAME_TEXT, "x-what": what}


def text(maximum=MAX_TEXT):
    return {"type": "string", "maxLength": maximum, "pattern": TEXT_PATTERN,
            "description": "text without control characters (newlines and tabs allowed)"}


SCENE = {"type": "string", "pattern": SCENE_PATTERN, "description": SCENE_TEXT}


def positive(maximum=None, unit=""):
    schema = {"type": "number", "exclusiveMinimum": 0, "description": "a finite number > 0" + unit}
    if maximum is not None:
        schema["maximum"] = maximum
    return schema


def whole(minimum, maximum):
    return {"type": "integer", "minimum": minimum, "maximum": maximum}


def positive_list(maximum=None, unit=""):
    return {"type": "array", "items": positive(maximum, unit), "minItems": 1, "maxItems": MAX_LIST,
            "uniqueItems": True}


def increasing_list(maximum=None, unit=""):
    """A list of numbers > 0 (the order is checked by the kind: JSON Schema has no 'increasing')."""
    return positive_list(maximum, unit)


def names_of(names, what):
    """One of `names` (from the registry)."""
    return {"enum": list(names), "x-what": what}


def name_list(names, what):
    return {"type": "array", "items": names_of(names, what), "minItems": 1, "maxItems": MAX_LIST, "uniqueItems": True}


def scene_list():
    return {"type": "array", "items": SCENE, "minItems": 1, "maxItems": MAX_LIST, "uniqueItems": True}


def forbidden(why):
    """A key that must not be given in this case (under if/then)."""
    return {"not": {}, "description": why}


def strict_map(properties, required=(), **more):
    """A map with exactly these keys (unknown keys refused, with the closest known name)."""
    schema = {"type": "object", "properties": properties, "additionalProperties": False}
    if required:
        schema["required"] = list(required)
    schema.update(more)
    return schema


DURATION = positive(1e7, " [s]")
TIME_LIMIT = positive(7 * 86400.0, " [s]")
SEED = whole(0, 2 ** 63 - 1)
COUNT = whole(1, MAX_TASKS)
EXPECT = {"enum": ["finish", "finish_or_refuse"], "x-what": "an expectation"}


def study(kind, experiment, extra=None, required=()):
    """The top level of a study of `kind`: name, kind, description, time_limit, experiments, and
    the kind's own keys."""
    properties = {"name": name("the study's name"), "kind": {"const": kind}, "description": text(),
                  "time_limit": TIME_LIMIT,
                  "experiments": {"type": "array", "items": experiment, "minItems": 1, "maxItems": MAX_LIST}}
    properties.update(extra or {})
    return strict_map(properties, ("name", "kind", "experiments") + tuple(required))


# --- the check ---------------------------------------------------------------------------------

def _document_order(doc, parts):
    """A sort key placing a problem where it is in the file (keys in their written order)."""
    key, node = [], doc
    for part in parts:
        if isinstance(node, dict) and part in node:
            key.append(list(node).index(part))
        elif isinstance(node, list) and isinstance(part, int) and part < len(node):
            key.append(part)
        else:
            break
        node = node[part]
    return key


def _closest(word, known):
    if not isinstance(word, str):
        return ""
    match = difflib.get_close_matches(word, [k for k in known if isinstance(k, str)], n=1, cutoff=0.6)
    return " (did you mean '%s'?)" % match[0] if match else ""


def _known(names, limit=20):
    names = [str(n) for n in names]
    shown = ", ".join(names[:limit])
    return shown + (", …" if len(names) > limit else "")


def _alternatives(names):
    """'a', 'b' or 'c'."""
    quoted_names = ["'%s'" % n for n in names]
    return " or ".join(quoted_names) if len(quoted_names) <= 2 else ", ".join(quoted_names[:-1]) + " or " + quoted_names[-1]


def _unknown(what, word, known):
    """"unknown key (did you mean 'steps'? known: ...)" or "unknown key (known: ...)"."""
    closest = _closest(word, known)
    return "unknown %s (%sknown: %s)" % (what, closest[2:-1] + " " if closest else "", _known(known))


def _message(error):
    """(key path parts, what is wrong) of one jsonschema error, in the study's words. The value is
    quoted short (limits.quoted); jsonschema's own message, which prints the whole value, is not used."""
    parts = tuple(error.absolute_path)
    schema, instance, rule = error.schema, error.instance, error.validator
    if "propertyNames" in error.schema_path:  # a map key that is not an allowed name
        known = schema.get("enum")
        if known is not None:
            return parts + (instance,), _unknown(schema.get("x-what", "name"), instance, known)
        return parts + (instance,), "must be %s" % schema.get("description", NAME_TEXT)
    if rule == "additionalProperties":
        known = list(schema.get("properties", {}))
        extra = next(k for k in instance if k not in known)
        return parts + (extra,), _unknown("key", extra, known)
    if rule == "required":
        missing = next(k for k in error.validator_value if k not in instance)
        return parts + (missing,), "required"
    if rule == "type":
        wanted = error.validator_value
        return parts, "must be %s, got %s" % (schema.get("description") if "description" in schema
                                               else TYPE_TEXT.get(wanted, wanted), quoted(instance))
    if rule in ("enum", "const"):
        known = error.validator_value if rule == "enum" else [error.validator_value]
        return parts, "must be %s, got %s%s" % (_alternatives(known) if len(known) <= 4 else "one of " + _known(known),
                                                quoted(instance), _closest(instance, known))
    if rule == "pattern":
        return parts, "must be %s, got %s" % (schema.get("description", "text of the allowed characters"),
                                              quoted(instance))
    if rule in ("exclusiveMinimum", "minimum", "maximum", "exclusiveMaximum"):
        sign = {"exclusiveMinimum": ">", "minimum": "≥", "maximum": "≤", "exclusiveMaximum": "<"}[rule]
        return parts, "must be %s %s, got %s" % (sign, quoted(error.validator_value), quoted(instance))
    if rule == "minItems":
        return parts, "must not be empty" if error.validator_value == 1 else \
            "needs at least %d values" % error.validator_value
    if rule == "maxItems":
        return parts, "holds %d values, more than the cap of %d (limits.MAX_LIST)" % (len(instance), error.validator_value)
    if rule == "uniqueItems":
        seen = []
        for item in instance:
            if item in seen:
                return parts, "holds %s twice" % quoted(item)
            seen.append(item)
        return parts, "holds a value twice"
    if rule == "minProperties":
        return parts, "must not be empty"
    if rule == "maxProperties":
        return parts, "holds %d keys, more than the cap of %d" % (len(instance), error.validator_value)
    if rule == "maxLength":
        return parts, "%d characters, more than the cap of %d" % (len(instance), error.validator_value)
    if rule == "minLength":
        return parts, "must not be empty"
    if rule == "not":
        return parts, schema.get("description", "not allowed here")
    return parts, "does not fit the schema (%s)" % rule


def check(path, doc, schema):
    """Refuses `doc` (StudyError) at its first problem in the file's order, naming the key."""
    errors = list(Validator(schema).iter_errors(doc))
    if not errors:
        return
    found = sorted((_message(e) for e in errors), key=lambda m: _document_order(doc, m[0]))
    parts, message = found[0]
    more = len({m for m in found}) - 1
    raise refusal(path, parts, message + (" (and %d more problem%s)" % (more, "" if more == 1 else "s") if more else ""))


def refuse(path, parts, message):
    """A refusal of the kinds' own checks (those JSON Schema cannot say), in the same form."""
    raise refusal(path, parts, message)


def cap_tasks(path, sizes):
    """Refuses a study whose experiments (their task counts, `sizes`, in order) expand to more than
    MAX_TASKS, naming the experiment that passes the cap: counted before any task is made."""
    total = 0
    for i, size in enumerate(sizes):
        total += size
        if total > MAX_TASKS:
            refuse(path, ("experiments", i), "the study expands to more than %d tasks, the cap (limits.MAX_TASKS)"
                   % MAX_TASKS)


def unique_labels(path, experiments):
    """Refuses an experiment whose label an earlier one has (labels name report sections and plots)."""
    labels = set()
    for i, experiment in enumerate(experiments):
        if experiment["label"] in labels:
            refuse(path, ("experiments", i, "label"), "'%s' is the label of an earlier experiment" % experiment["label"])
        labels.add(experiment["label"])
