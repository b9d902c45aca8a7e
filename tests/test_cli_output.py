"""What the command line shows a person: progress, help, the scene list, counts, closed pipes."""

from __future__ import annotations

import argparse
import io
import os
import subprocess
import sys
from types import SimpleNamespace

import pytest

from wire_fmu.cli import _parser, main
from wire_fmu.cli_commands import EXIT_BROKEN_PIPE, first_sentence, plural
from wire_fmu.master.observers import Progress, _duration
from wire_fmu.master.run import shipped_scenes
from wire_fmu.master.scene import load_scene


class _Stream(io.StringIO):
    def __init__(self, terminal: bool) -> None:
        super().__init__()
        self.terminal = terminal

    def isatty(self) -> bool:
        return self.terminal


def _fake_run(progress: Progress, steps: int = 1000, stop: float = 10.0) -> None:
    """Drive ``progress`` through a run of ``steps`` equal steps to ``stop`` (s)."""
    sim = SimpleNamespace(
        scene=SimpleNamespace(name="demo"),
        run_settings=SimpleNamespace(stop_time=stop),
        time=0.0,
    )
    progress.on_start(sim)
    for i in range(1, steps + 1):
        sim.time = stop * i / steps
        progress.on_step(sim)
    progress.on_end(sim, SimpleNamespace(status="finished"))


def test_progress_writes_plain_lines_without_carriage_returns_when_redirected():
    stream = _Stream(terminal=False)
    _fake_run(Progress(stream))
    text = stream.getvalue()
    assert "\r" not in text
    lines = text.splitlines()
    # one line per tenth done (10 % ... 90 %) and the final one
    assert len(lines) == 10
    assert [line.split("]")[1].split("%")[0].strip() for line in lines] == [
        f"{p:.1f}" for p in range(10, 101, 10)
    ]
    assert all("left" in line for line in lines[:-1])
    assert "took" in lines[-1] and "100.0 %" in lines[-1]


def test_progress_redraws_one_line_in_place_on_a_terminal_with_the_time_left():
    stream = _Stream(terminal=True)
    progress = Progress(stream, every=0.0)
    _fake_run(progress, steps=50)
    text = stream.getvalue()
    assert text.count("\n") == 1 and text.endswith("\n")  # one line, ended once
    assert text.count("\r") == 51  # every step redrawn (every=0) and the end
    assert "left" in text and "took" in text


def test_progress_on_a_stream_without_isatty_is_taken_as_redirected():
    class Bare:
        def __init__(self) -> None:
            self.parts: list[str] = []

        def write(self, text: str) -> None:
            self.parts.append(text)

        def flush(self) -> None:
            pass

    stream = Bare()
    _fake_run(Progress(stream), steps=20)
    assert "\r" not in "".join(stream.parts)


@pytest.mark.parametrize(
    ("seconds", "text"),
    [(0.04, "0.0 s"), (3.26, "3.3 s"), (42.4, "42 s"), (185.0, "3 min 05 s"), (3720, "1 h 02 min")],
)
def test_durations_read_as_people_write_them(seconds, text):
    assert _duration(seconds) == text


def _all_parsers(parser: argparse.ArgumentParser):
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                yield from _all_parsers(sub)


def test_no_help_text_shows_restructuredtext_markup():
    parsers = list(_all_parsers(_parser()))
    assert len(parsers) > 8  # the commands and the study kinds
    for parser in parsers:
        text = parser.format_help()
        assert "``" not in text, f"{parser.prog}: raw markup in its help"
        assert ":class:" not in text and ":func:" not in text, parser.prog


@pytest.mark.parametrize(
    ("text", "sentence"),
    [
        ("One line. Two.", "One line."),
        (
            "Riser tensioner (paper 000, Fig. 6). Watch tension.",
            "Riser tensioner (paper 000, Fig. 6).",
        ),
        ("A load\nover two lines; the rest.\nWatch it.", "A load over two lines; the rest."),
        ("The lift and the test. 'lift' turns.", "The lift and the test."),
        ("No full stop", "No full stop"),
    ],
)
def test_first_sentence_is_whole_and_joined(text, sentence):
    assert first_sentence(text) == sentence


def test_scenes_lists_each_shipped_scene_with_its_whole_first_sentence(capsys):
    assert main(["scenes"]) == 0
    out = capsys.readouterr().out
    flowing = " ".join(out.split())
    for name, path in shipped_scenes().items():
        sentence = first_sentence(load_scene(path).description)
        assert sentence.endswith((".", "!", "?")), (name, sentence)
        # wrapping may split a hyphenated word at its hyphen; nothing else is changed
        assert f"{name} {sentence}".replace("- ", "-") in flowing.replace("- ", "-"), name


@pytest.mark.parametrize(
    ("count", "noun", "text"),
    [(0, "bond", "0 bonds"), (1, "bond", "1 bond"), (2, "unit", "2 units"), (1, "case", "1 case")],
)
def test_counts_are_pluralised(count, noun, text):
    assert plural(count, noun) == text


def test_check_says_one_bond_not_one_bonds(capsys):
    assert main(["check", "drawworks"]) == 0
    out = capsys.readouterr().out
    assert "1 bond," in out and "1 bonds" not in out and "0 connections" in out


def test_a_closed_pipe_ends_the_command_quietly():
    """``wire-fmu scenes | head -1``: the reader is gone before the listing is written."""
    read_end, write_end = os.pipe()
    os.close(read_end)  # every write to the pipe now fails (EPIPE)
    try:
        done = subprocess.run(
            [
                sys.executable,
                "-c",
                "import sys; from wire_fmu.cli import main; sys.exit(main())",
                "scenes",
            ],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
            check=False,
        )
    finally:
        os.close(write_end)
    assert done.stderr == ""  # no traceback, no "Exception ignored"
    assert done.returncode == EXIT_BROKEN_PIPE
