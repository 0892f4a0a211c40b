"""Library messages in the command line's words: a field the library names (```wind_offset_s```) is its flag.

The library's errors, warnings and notes name the option a caller sets, as the field or argument of the
library call (```wind_distance_m``` of ``ConditioningOptions``), in backquotes; a Python or batch caller
reads them so. The command line shows the flag that sets it instead, where the running command has that
flag; where it has not (``sysid batch`` has no ``--segments``), the field stays named, and said not to be
an option of the command.
"""

from __future__ import annotations

import re

import click

__all__ = ["FLAGS", "RUNNING", "as_flags"]

RUNNING = "sysid.running"  # ctx.meta key: the context of the command running (set by SysidCommand.invoke)

#: Field or argument the library names -> (the click parameter that sets it, the flag shown).
FLAGS: dict[str, tuple[str, str]] = {
    "wind_paths": ("wind_paths", "--wind"),
    "wind_offset_s": ("wind_offset", "--wind-offset"),
    "estimate_wind_offset": ("estimate_wind_offset", "--estimate-wind-offset"),
    "wind_distance_m": ("wind_distance", "--wind-distance"),
    "wind_bearing_rad": ("wind_bearing", "--wind-bearing"),
    "anemometer_position_rad": ("anemometer_at", "--anemometer-at"),
    "transport_delay_s": ("transport_delay", "--transport-delay"),
    "segments": ("segments_file", "--segments"),
    "partial": ("partial", "--partial"),
    "min_coherence": ("min_coherence", "--min-coherence"),
    "force_multirotor": ("vehicle", "--vehicle multirotor"),
    "columns": ("columns", "--columns"),
    "mass_kg": ("mass", "--mass"),
    "mapping": ("mapping", "--mapping"),
}

_FIELD = re.compile(r"`(\w+)`")


def as_flags(text: str, ctx: click.Context | None = None) -> str:
    """`text` with each field in backquotes replaced by the running command's flag for it.

    Parameters
    ----------
    text : str
        A library message.
    ctx : click.Context, optional
        The command's context (default: that of the command running, which a group's context also knows);
        without a command, the text as it is.

    Returns
    -------
    str

    Examples
    --------
    >>> @click.command()
    ... @click.option("--wind-offset", type=float)
    ... def fit(wind_offset): ...
    >>> with click.Context(fit, info_name="fit") as ctx:
    ...     print(as_flags("the clock is off: give `wind_offset_s` or `segments`", ctx))
    the clock is off: give --wind-offset or `segments`, not an option of fit
    """
    ctx = ctx if ctx is not None else click.get_current_context(silent=True)
    if ctx is None:
        return text
    ctx = ctx.meta.get(RUNNING, ctx)
    own = {param.name for param in ctx.command.params}
    group, *rest = ctx.command_path.split()  # "sysid" as the user typed it, whatever the group's own name
    command = " ".join(["sysid", *rest]) if rest else group

    def flag(match: re.Match[str]) -> str:
        known = FLAGS.get(match.group(1))
        if known is None:
            return match.group(0)
        name, shown = known
        if name in own:
            return shown
        return f"{match.group(0)}, not an option of {command}"

    return _FIELD.sub(flag, text)
