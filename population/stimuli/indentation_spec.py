"""Indentation stimuli from a table of named settings: ``ddmm simulate --indent``'s and a stimulus file's.

One table (a dict: from ``KIND:key=value,...`` on the command line or a TOML
file) names a waveform ``kind`` and its settings, the pins and the skin:

- ``kind``: ``ramp`` (`ramp_hold`: ``depth_mm``, ``ramp_s``, ``hold_s``),
  ``sine`` (`sinusoid`: ``freq_hz``, ``amplitude_mm``, ``pre_indent_mm``,
  ``duration_s``, ``ramp_s``, ``phase_deg``), ``noise`` (`band_noise`:
  ``low_hz``, ``high_hz``, ``sd_mm``, ``pre_indent_mm``, ``duration_s``,
  ``ramp_s``, ``seed``) or ``impulse`` (`impulse`: ``amplitude_mm``,
  ``width_s``, ``pad_s``, ``pre_indent_mm``); ``fs`` (Hz) for every kind;
- ``pins``: ``probe`` (``x_mm``, ``y_mm``, ``radius_mm``), ``array``
  (``rows``, ``cols``, ``pitch_mm``, ``x_mm``, ``y_mm``, ``radius_mm``), ``bar``
  (``width_mm``, ``height_mm``, ``angle_deg``, ``pins_per_mm``, ``x_mm``,
  ``y_mm``) or ``circle`` (``disc_radius_mm``, ``curvature_mm``, ``pins_per_mm``,
  ``x_mm``, ``y_mm``); default ``probe``;
- ``lateral_mm`` and ``lateral_deg``: the pins slide by ``lateral_mm`` along
  ``lateral_deg`` (0 radial, 90 distal) at a constant speed over the middle
  third of the stimulus, and stay there (default 0: no sideways motion);
- ``skin``: ``default`` or ``touchsim``; ``transduction``: ``fitted`` (default) or ``none``
  (`ddmm.population.stimuli.transduction`); ``name``: the condition's name.

Every unknown key, kind or pin shape, and a key given twice, is refused with a
`ValueError` naming it and what is allowed; a value that is not text or a
number (a TOML table or list) with a `TypeError` naming its key.
"""

from __future__ import annotations

import numpy as np

from ddmm.population.stimuli import indentation as ind
from ddmm.utils.validation import shown

__all__ = ["KINDS", "PIN_SHAPES", "indentation_from_dict", "parse_indent_option"]

#: Waveform kinds and the settings each takes (beside ``fs``).
KINDS = {
    "ramp": (ind.ramp_hold, ("depth_mm", "ramp_s", "hold_s")),
    "sine": (ind.sinusoid, ("freq_hz", "amplitude_mm", "pre_indent_mm", "duration_s", "ramp_s", "phase_deg")),
    "noise": (ind.band_noise, ("low_hz", "high_hz", "sd_mm", "pre_indent_mm", "duration_s", "ramp_s", "seed")),
    "impulse": (ind.impulse, ("amplitude_mm", "width_s", "pad_s", "pre_indent_mm")),
}
#: Pin shapes and the settings each takes.
PIN_SHAPES = {
    "probe": ("x_mm", "y_mm", "radius_mm"),
    "array": ("rows", "cols", "pitch_mm", "x_mm", "y_mm", "radius_mm"),
    "bar": ("width_mm", "height_mm", "angle_deg", "pins_per_mm", "x_mm", "y_mm"),
    "circle": ("disc_radius_mm", "curvature_mm", "pins_per_mm", "x_mm", "y_mm"),
}
_COMMON = ("kind", "fs", "pins", "lateral_mm", "lateral_deg", "skin", "transduction", "name")
#: The settings that are text (every other one is a number).
_TEXT = ("kind", "pins", "skin", "transduction", "name")


def indentation_from_dict(table: dict):
    """The indentation `Scene` a settings table describes (module docstring).

    Examples
    --------
    >>> s = indentation_from_dict({"kind": "sine", "freq_hz": 100.0, "amplitude_mm": 0.05,
    ...                            "pre_indent_mm": 0.3, "duration_s": 0.2})
    >>> s.name, s.fs
    ('sine_100hz', 5000.0)
    """
    if not isinstance(table, dict):
        raise TypeError(f"an indentation must be a table of settings, got {type(table).__name__}")
    for key, value in table.items():  # a TOML file may give a table, a list or a date: refused by key
        if isinstance(value, bool) or not isinstance(value, (str, int, float)):
            got = {dict: "a table", list: "a list"}.get(type(value), type(value).__name__)
            raise TypeError(f"indent key {key!r} must be {'text' if key in _TEXT else 'a number'}, got {got}")
    kind = table.get("kind")
    if kind not in KINDS:
        raise ValueError(f"indent kind {kind!r} is unknown; allowed: {', '.join(KINDS)}")
    make, settings = KINDS[kind]
    shape = table.get("pins", "probe")
    if shape not in PIN_SHAPES:
        raise ValueError(f"indent pins {shape!r} is unknown; allowed: {', '.join(PIN_SHAPES)}")
    unknown = sorted(set(table) - set(_COMMON) - set(settings) - set(PIN_SHAPES[shape]))
    if unknown:
        raise ValueError(f"indent key {unknown[0]!r} does not apply to kind {kind!r} with pins {shape!r}; allowed: "
                         f"{', '.join(sorted(set(_COMMON) | set(settings) | set(PIN_SHAPES[shape])))}")
    fs = table.get("fs", ind.INDENT_FS)
    args = {k: table[k] for k in settings if k in table}
    if "seed" in args:
        args["rng"] = args.pop("seed")
    depth = make(**args, fs=fs)
    pins = _pins(shape, table)
    lateral = _lateral_ramp(table, depth.size, len(pins))
    name = table.get("name", _default_name(kind, table))
    return ind.indent(pins, depth, fs=fs, lateral_mm=lateral, skin=table.get("skin", "default"),
                      transduction=str(table.get("transduction", "fitted")), name=str(name))


def _pins(shape: str, table: dict):
    from ddmm.utils.validation import check_positive, check_real

    centre = tuple(check_real(table.get(key, 0.0), key, "mm") for key in ("x_mm", "y_mm"))
    if shape == "probe":
        return ind.probe(*centre, radius_mm=table.get("radius_mm", 0.5))
    if shape == "array":
        return ind.pin_array(table.get("rows", 1), table.get("cols", 1), pitch_mm=table.get("pitch_mm", 1.0),
                             center_mm=centre, radius_mm=table.get("radius_mm"))
    if shape == "bar":
        return ind.bar_pins(table.get("width_mm", 1.0), table.get("height_mm", 0.5),
                            angle_deg=table.get("angle_deg", 0.0), pins_per_mm=table.get("pins_per_mm", 10.0),
                            center_mm=centre)
    radius = check_positive(table.get("disc_radius_mm", 2.0), "disc_radius_mm", "mm")  # named as the table names it
    return ind.circle_pins(radius, curvature_mm=table.get("curvature_mm", 0.0),
                           pins_per_mm=table.get("pins_per_mm", 10.0), center_mm=centre)


def _lateral_ramp(table: dict, n: int, n_pins: int):
    """(n, 2) mm: a slide of ``lateral_mm`` along ``lateral_deg`` over the middle third, or None."""
    distance, angle = table.get("lateral_mm", 0.0), table.get("lateral_deg", 0.0)
    for key, value in (("lateral_mm", distance), ("lateral_deg", angle)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
            raise ValueError(f"indent {key} must be a number, got {shown(value)}")
    if not 0.0 <= distance <= 10.0:
        raise ValueError(f"indent lateral_mm must be in [0, 10] mm, got {shown(distance)}")
    if distance == 0.0:
        return None
    path = np.clip((np.arange(n) - n / 3.0) / (n / 3.0), 0.0, 1.0) * distance
    a = np.deg2rad(angle)
    return np.column_stack([path * np.cos(a), path * np.sin(a)])


def _default_name(kind: str, table: dict) -> str:
    if kind == "sine":
        return f"sine_{float(table.get('freq_hz', 0.0)):g}hz"
    if kind == "ramp":
        return f"ramp_{float(table.get('depth_mm', 0.0)):g}mm"
    return kind


def parse_indent_option(text: str) -> dict:
    """The settings table of ``--indent KIND[:key=value,...]`` (numbers where they parse, else text).

    Examples
    --------
    >>> parse_indent_option("sine:freq_hz=250,amplitude_mm=0.02,pre_indent_mm=0.3,skin=touchsim")["freq_hz"]
    250.0
    """
    from ddmm.utils.validation import parse_number

    kind, _, rest = text.partition(":")
    table = {"kind": kind.strip()}
    for item in filter(None, (p.strip() for p in rest.split(","))):
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise ValueError(f"--indent settings must be key=value, got {item!r}")
        if key.strip() in table:
            raise ValueError(f"--indent key {key.strip()!r} is given twice; give each key once")
        try:
            table[key.strip()] = parse_number(value.strip())
        except ValueError:
            table[key.strip()] = value.strip()
    for key in ("rows", "cols", "seed"):
        if isinstance(table.get(key), float) and float(table[key]).is_integer():
            table[key] = int(table[key])
    return table
