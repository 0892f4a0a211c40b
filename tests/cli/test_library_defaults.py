"""Issue 33, one owner per value: a command's default is the library's, read from it, never typed again."""

from __future__ import annotations

import click
import pytest

from sysid_cli._common import LibraryDefault
from sysid_cli.main import cli


def _options() -> list[tuple[str, click.Option]]:
    """Every option of every command and subcommand, with the command's path."""
    found = []

    def walk(command: click.Command, path: str) -> None:
        for param in command.params:
            if isinstance(param, click.Option):
                found.append((path, param))
        if isinstance(command, click.Group):  # the commands load when asked for (sysid_cli.main's lazy group)
            with click.Context(command) as ctx:
                for name in command.list_commands(ctx):
                    sub = command.get_command(ctx, name)
                    assert sub is not None
                    walk(sub, f"{path} {name}")

    walk(cli, "sysid")
    return found


#: Options whose value a library dataclass or function also declares (the library owns it).
OWNED = {
    "min_coherence", "min_decades", "max_cr", "max_insensitivity", "omega_min", "omega_max", "n_freq", "overlap",
    "starts", "before_s", "after_s", "kf", "pwm_full_scale", "rotor_offset", "min_hold", "confidence", "criterion",
    "rotors", "trials", "pid_phase", "mrac_phase",
}  # fmt: skip


def test_every_owned_default_is_read_from_the_library() -> None:
    seen = set()
    for path, option in _options():
        if option.name in OWNED and not isinstance(option, LibraryDefault):  # one without a default (simulate --trials)
            typed = option.get_default(click.Context(cli))
            assert not isinstance(typed, (int, float, str)), f"{path} {option.opts[0]} types its default again"
        elif option.name in OWNED:
            seen.add(option.name)
    assert seen == OWNED  # each is an option of some command (a renamed one would pass unseen)


def _default(command: str, flag: str) -> object:
    (option,) = [o for path, o in _options() if path == f"sysid {command}" and flag in o.opts]
    with click.Context(cli) as ctx:
        return option.get_default(ctx)


def test_the_defaults_are_the_libraries_values() -> None:
    from simulator.mrac.compare import CompareConfig
    from sysid.fit import DEFAULT_GUIDELINES, FitOptions
    from sysid.freqresp import Gating, ResponseOptions
    from sysid.verify.records import AFTER_S

    assert _default("fit", "--min-coherence") == _default("freqresp", "--min-coherence") == Gating().min_coherence
    assert _default("fit", "--min-decades") == Gating().min_decades
    assert _default("fit", "--max-cr") == DEFAULT_GUIDELINES.max_cr_percent
    assert _default("fit", "--starts") == FitOptions().starts
    assert _default("freqresp", "--n-freq") == ResponseOptions().n_freq
    assert _default("validate", "--after") == AFTER_S
    assert _default("mrac compare", "--trials") == CompareConfig().trials


def test_a_default_changed_in_the_library_is_the_commands(monkeypatch: pytest.MonkeyPatch) -> None:
    from sysid.freqresp import Gating

    monkeypatch.setattr(Gating.__dataclass_fields__["min_coherence"], "default", 0.61)
    assert _default("fit", "--min-coherence") == _default("freqresp", "--min-coherence") == 0.61
