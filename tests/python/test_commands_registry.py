"""One registry of commands: the C++ program's command tree (apps/program.cpp registers them; `_afmkit.commands()`
lists them) is the source, and every other place that names the commands agrees with it — the program's --help,
the Python functions (generated from it), the command-line tests' list (tests/cli/help_walk.hpp), docs/commands.md —
so a command added, renamed or removed in one place and not in another fails here. `report` and `study run` take
the options the program declares (argparse generated from the C++ ParamSet): the same keys and defaults."""
import importlib
import os
import re
import subprocess
from pathlib import Path

import pytest

import afmkit
from afmkit import _commands

SOURCE = Path(os.environ.get("AFMKIT_SOURCE_DIR", Path(__file__).resolve().parents[2]))
CLI = os.environ.get("AFMKIT_CLI")
PATHS = [s["path"] for s in _commands.commands()]
RUNNABLE = {s["path"] for s in _commands.commands() if s["runnable"]}


def _resolve(dotted: str):
    """afmkit.<dotted> ("tapping.orbit", "report.build"), importing the submodules on the way."""
    obj = afmkit
    for part in dotted.split("."):
        if not hasattr(obj, part):
            obj = importlib.import_module(f"{obj.__name__}.{part}")
        else:
            obj = getattr(obj, part)
    return obj


def _help(*args) -> str:
    r = subprocess.run([CLI, *args, "--help"], capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stderr
    return r.stdout


def _subcommands(help_text: str) -> list:
    listing = help_text.split("\nSubcommands:\n", 1)
    return re.findall(r"^  ([a-z]+)\s", listing[1], re.M) if len(listing) == 2 else []


def test_the_registry_is_every_leaf_command_once():
    assert len(PATHS) == len(set(PATHS)) >= 20
    assert {"report", "study run", "tapping grid"} <= set(PATHS) - RUNNABLE  # Python programs, a store


@pytest.mark.skipif(not CLI, reason="AFMKIT_CLI not set")
def test_the_programs_help_lists_exactly_the_registry():
    leaves = []
    for top in _subcommands(_help()):
        subs = _subcommands(_help(top))
        leaves += [f"{top} {s}" for s in subs] if subs else [top]
    assert sorted(leaves) == sorted(PATHS)


def test_every_command_is_in_python_where_the_registry_says():
    for path in PATHS:
        obj = _resolve(_commands.python_name(path))
        assert callable(obj), path
        if path in RUNNABLE and path not in _commands._ELSEWHERE:  # a generated command function
            assert getattr(obj, "__afmkit_command__", None) == path, path


def test_every_command_function_of_the_package_runs_a_command_of_the_registry():
    found = {}
    for name in ("afmkit", "afmkit.tapping", "afmkit.control", "afmkit.spectroscopy", "afmkit.spectroscopy_fit",
                 "afmkit.spectroscopy_reconstruct"):
        module = importlib.import_module(name)
        for attr in dir(module):
            path = getattr(getattr(module, attr), "__afmkit_command__", None)
            if path is not None:
                found[f"{name}.{attr}"] = path
    assert set(found.values()) <= RUNNABLE, found
    # every runnable command has its function (spectroscopy prepare: prepare_file, a wrapper in SI units)
    assert RUNNABLE - set(found.values()) <= {"spectroscopy prepare"}
    with pytest.raises(ValueError, match="no afmkit command 'tapping nothing'"):
        _commands.make_command("tapping nothing")


def test_the_command_line_tests_list_every_command():
    text = (SOURCE / "tests" / "cli" / "help_walk.hpp").read_text()
    block = re.search(r"kCommands\s*=\s*\{(.*?)\};", text, re.S)
    assert block, "kCommands not found in tests/cli/help_walk.hpp"
    listed = re.findall(r'"([a-z ]+)"', block.group(1))
    assert sorted(listed) == sorted(PATHS), "tests/cli/help_walk.hpp kCommands differs from the program's commands"


def test_the_commands_page_documents_every_command():
    page = (SOURCE / "docs" / "commands.md").read_text()
    headings = re.findall(r"^## afmkit ([a-z ]+?)(?: …)? —", page, re.M)
    for path in PATHS:
        group, _, name = path.rpartition(" ")
        # its own section, or an item `name`: in the section of its group (afmkit control …)
        own = path in headings
        in_group = group in headings and f"\n* `{name}`: " in page
        assert own or in_group, f"docs/commands.md has no section for `afmkit {path}`"


def _declared_in_help(help_text: str) -> dict:
    """key -> default text as `afmkit <command> --help` prints it ("[default 2]", "[unit: s; default 1; …]")."""
    out = {}
    for flag, rest in re.findall(r"^\s+--([a-z0-9-]+)(?: [A-Z.,]+)?(?: Excludes: \S+)?\s+(.*)$", help_text, re.M):
        m = re.search(r"[\[;] ?default (.*?)(?:;|\]$)", rest)
        if m and flag not in ("help", "config"):
            out[flag.replace("-", "_")] = m.group(1)
    return out


def _as_text(value) -> str:
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, str):
        return f"'{value}'"
    return f"{value:g}" if isinstance(value, float) else str(value)


@pytest.mark.skipif(not CLI, reason="AFMKIT_CLI not set")
def test_report_takes_the_options_and_defaults_the_program_declares():
    from afmkit.report.__main__ import make_parser

    declared = _declared_in_help(_help("report"))
    args = vars(make_parser().parse_args([]))
    assert set(args) == set(declared) == {"output_dir", "jobs", "figures"}
    for key, value in args.items():
        assert _as_text(value) == declared[key], key


@pytest.mark.skipif(not CLI, reason="AFMKIT_CLI not set")
def test_study_run_takes_the_options_the_program_declares_and_its_defaults_after_the_files_run_table():
    from afmkit.study.__main__ import RUN_FIELDS, make_parser

    declared = _declared_in_help(_help("study", "run"))
    args = vars(make_parser().parse_args(["run", "s.toml"]))
    args.pop("action")
    assert set(args) == set(declared) and args["file"] == "s.toml"
    # not given: None (the file's [run] table comes next), then the declared default where it is a value
    assert all(v is None for k, v in args.items() if k not in ("file", "quiet")) and args["quiet"] is False
    defaults = _commands.declared_defaults("study run")
    for key, value in defaults.items():
        if value is not None and key != "file":
            assert _as_text(value) == declared[key], key
    assert set(RUN_FIELDS) == set(declared) - {"file", "quiet"}
    given = vars(make_parser().parse_args(["run", "s.toml", "--chunk-seconds", "2.5", "--workers", "3", "--quiet"]))
    assert (given["chunk_seconds"], given["workers"], given["quiet"]) == (2.5, 3, True)


def test_the_bad_input_page_has_rows_for_every_command():
    rows = [line for line in (SOURCE / "docs" / "bad-input.md").read_text().splitlines() if line.startswith("|")]
    for path in PATHS:  # (tests/cli/test_bad_input.cpp runs the rows)
        assert any(re.search(rf"afmkit {path}(?![a-z])", r) for r in rows), f"docs/bad-input.md: no row for {path}"


def test_a_studys_computations_are_commands_of_the_registry_by_their_python_names():
    from afmkit.study.definition import COMPUTATIONS

    for name, path in COMPUTATIONS.items():
        assert path in RUNNABLE and _commands.python_name(path) == name, (name, path)
