"""Help that helps (issue 25, point 8): every option of every command has help text and
its help shows the default.  The reference is the parser itself, built as
``gearsym.cli.main`` builds it, so a new option without help fails here."""

from __future__ import annotations

import argparse
import re

import pytest
from gearsym.cli import _parser


def _commands() -> dict[str, argparse.ArgumentParser]:
    parser = _parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return {"gearsym": parser, **sub.choices}


COMMANDS = _commands()


def _needs_default(action: argparse.Action) -> bool:
    """An option that takes a value and has one when not given (flags are False)."""
    return (
        bool(action.option_strings)
        and action.nargs != 0
        and action.default not in (None, False, argparse.SUPPRESS)
    )


def test_every_command_is_walked():
    assert {"derive", "simulate", "sweep", "shoot", "continue", "map", "frequency-response"} <= set(
        COMMANDS
    )


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_option_has_help(name):
    parser = COMMANDS[name]
    missing = [
        "/".join(a.option_strings) or a.dest
        for a in parser._actions
        if not isinstance(a, argparse._HelpAction | argparse._SubParsersAction)
        and not (a.help or "").strip()
    ]
    assert not missing, f"{name}: options without help: {missing}"


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_default_is_shown(name):
    parser = COMMANDS[name]
    # argparse wraps lines; compare with runs of white space made one space
    text = re.sub(r"\s+", " ", parser.format_help())
    for action in filter(_needs_default, parser._actions):
        shown = f"(default: {action.default})"
        assert shown in text, f"{name} {action.option_strings[0]}: {shown} not in --help"


def test_flags_and_unset_options_show_no_default():
    """The formatter adds the default only where there is one (no "(default: None)")."""
    for name, parser in COMMANDS.items():
        text = parser.format_help()
        assert "(default: None)" not in text, name
        assert "(default: False)" not in text, name


def test_help_shows_one_default_per_option():
    """The old prose defaults ("(300; at most ...)", "(default 7)") are gone, so a default
    is not said twice, perhaps differently."""
    text = re.sub(r"\s+", " ", COMMANDS["simulate"].format_help())
    assert "periods discarded (at most 1,000,000) (default: 300)" in text
    text = re.sub(r"\s+", " ", COMMANDS["backlash"].format_help())
    assert "(default 7)" not in text and "(default: 7)" in text
