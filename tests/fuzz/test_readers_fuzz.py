"""Every reader, fed damaged input, raises only KinestatError (issue 11, bad input).

Two kinds of input per reader, within the hypothesis profile of tests/conftest.py:

- a valid seed (the embedded models, platform, decks; URDF exported from them; pose and axes
  files) after 1-4 random mutations (tests/fuzz/corpus.py: huge integers, deep nesting, wrong
  types, binary bytes, swapped names, truncation, ...);
- for the TOML/JSON formats, the seed document with one field (at any depth) replaced by an
  arbitrary value: integers far beyond a float, NaN, strings, booleans, lists, tables.

Whatever the input, the reader returns a result or raises a KinestatError; any other exception
fails the test.
"""

from __future__ import annotations

import json
import random
import tomllib

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinestat.errors import KinestatError
from tests.fuzz.corpus import READERS, mutate, seeds

_SUPPRESS = [HealthCheck.too_slow, HealthCheck.data_too_large]


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


def _feed(name: str, text: str, workdir) -> None:
    try:
        READERS[name].call(text, workdir)
    except KinestatError:
        pass


@pytest.mark.parametrize("name", sorted(READERS))
def test_seeds_are_accepted(name, workdir):
    # the mutations start from valid input, so they probe the checks, not only the syntax
    for text in seeds(name):
        READERS[name].call(text, workdir)


@pytest.mark.parametrize("name", sorted(READERS))
@settings(suppress_health_check=_SUPPRESS)
@given(data=st.data())
def test_mutated_input_raises_only_kinestat_errors(name, workdir, data):
    rng = data.draw(st.randoms(use_true_random=False), label="rng")
    text = mutate(rng, rng.choice(seeds(name)))
    _feed(name, text, workdir)


_KEYS = st.sampled_from(["name", "notation", "joints", "type", "pitch", "limits", "theta", "d",
                         "a", "alpha", "r", "angle_unit", "length_unit", "base", "tool",
                         "q_home", "frame_points", "hand", "design", "legs", "kind", "stiffness",
                         "home_pose", "leg_names", "axes", "point", "direction", "plucker",
                         "tol", "pose", "free_lengths", "x", "force_unit", "force_sense",
                         "sensor", "leg", "length", "force", "length_counts", "lengths",
                         "force_degree"]) | st.text(max_size=4)
_SCALARS = (
    st.integers()
    | st.integers(min_value=10**300, max_value=10**1000)
    | st.integers(min_value=-(10**1000), max_value=-(10**300))
    | st.floats()
    | st.booleans()
    | st.text(max_size=8)
    | st.sampled_from(["[/]", "[bold]x", "deg", "rad", "mm", "N", "revolute", "prismatic",
                      "screw", "standard_dh", "modified_dh", "nadkarni", "special-6-6"])
)
_VALUES = st.recursive(_SCALARS, lambda inner: st.lists(inner, max_size=6)
                       | st.dictionaries(_KEYS, inner, max_size=4), max_leaves=24)
_STRUCTURED = {
    "model_toml": "toml", "platform_toml": "toml", "axes_toml": "toml", "axes_json": "json",
    "pose_json": "json", "pose_toml": "toml", "calibration_toml": "toml",
    "control_calibration": "toml",
}


def _replace_somewhere(doc, rng: random.Random, value):
    """``doc`` with the value at a random path (a dict key or list index, any depth) replaced
    by ``value`` (or a new key added)."""
    node, depth = doc, rng.randint(0, 4)
    for _ in range(depth):
        children = (list(node.values()) if isinstance(node, dict)
                    else node if isinstance(node, list) else [])
        children = [c for c in children if isinstance(c, (dict, list)) and c]
        if not children:
            break
        node = rng.choice(children)
    if isinstance(node, dict):
        key = rng.choice([*node, "x"]) if node else "x"
        node[key] = value
    elif isinstance(node, list) and node:
        node[rng.randrange(len(node))] = value
    return doc


@pytest.mark.parametrize("name", sorted(_STRUCTURED))
@settings(suppress_health_check=_SUPPRESS)
@given(data=st.data())
def test_any_value_in_any_field_raises_only_kinestat_errors(name, workdir, data):
    rng = data.draw(st.randoms(use_true_random=False), label="rng")
    value = data.draw(_VALUES, label="value")
    text = rng.choice(seeds(name))
    if _STRUCTURED[name] == "toml":
        doc = _replace_somewhere(tomllib.loads(text), rng, value)
        text = tomli_w.dumps(doc if isinstance(doc, dict) else {"pose": doc})
    else:
        text = json.dumps(_replace_somewhere(json.loads(text), rng, value))
    _feed(name, text, workdir)


def _numeric_paths(node, path=()):
    """The paths (keys and indices) of every number in a parsed document."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _numeric_paths(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _numeric_paths(v, path + (i,))
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        yield path


#: readers whose every number is bounded by ``kinestat.io._fields.MAX_MAGNITUDE``
_BOUNDED = {"platform_toml", "axes_toml", "axes_json", "pose_json", "pose_toml"}


@pytest.mark.parametrize("name", sorted(_STRUCTURED))
def test_a_huge_number_in_any_field_never_leaks_a_numpy_overflow(name, workdir):
    """Every number of every seed set in turn to ±1.7e308 or 1e200: NumPy never warns of an
    overflow on the way, and only kinestat errors are raised. The platform, axes and pose files
    refuse the value (``_fields.MAX_MAGNITUDE``), the first two naming its field; before the
    bound, 45 fields of the platform and axes files overflowed in products first (a
    RuntimeWarning, then an error far from the field)."""
    import copy
    import warnings

    fmt = _STRUCTURED[name]
    checked = 0
    for text in seeds(name):
        base = tomllib.loads(text) if fmt == "toml" else json.loads(text)
        for path in _numeric_paths(base):
            for value in (1.7e308, -1.7e308, 1e200):
                doc = copy.deepcopy(base)
                node = doc
                for key in path[:-1]:
                    node = node[key]
                node[path[-1]] = value
                out = tomli_w.dumps(doc) if fmt == "toml" else json.dumps(doc)
                with warnings.catch_warnings():
                    warnings.simplefilter("error", RuntimeWarning)
                    try:
                        READERS[name].call(out, workdir)
                    except KinestatError as exc:
                        if name in _BOUNDED:
                            assert "implausibly large" in str(exc), (path, str(exc))
                    else:
                        assert name not in _BOUNDED, f"{path} = {value} was accepted"
                checked += 1
    assert checked > 0
