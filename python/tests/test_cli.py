"""The command's convention (docs/cli.md): one module a subcommand with add_parser and run, the
argument types and the error helper in cli_args (no command imports cli), the exit codes
documented once and equal to the code's, and no function of the package over 150 lines."""
from __future__ import annotations

import ast
import importlib
import re

import pytest

from gauss6 import cli, cli_args, paths

PACKAGE = paths.REPO_ROOT / "python" / "gauss6"
MAX_FUNCTION_LINES = 150  # the project's bound on a function's length (issue 44)


def test_every_command_module_is_assembled_and_has_the_two_functions():
    modules = sorted(p.stem for p in (PACKAGE / "commands").glob("*.py") if p.stem != "__init__")
    assert sorted(cli.COMMANDS) == modules
    for name in cli.COMMANDS:
        module = importlib.import_module(f"gauss6.commands.{name}")
        assert callable(module.add_parser) and callable(module.run), name


@pytest.mark.parametrize("name", cli.COMMANDS)
def test_each_command_parses_its_help(name, capsys):
    command = name.replace("_", "-")
    assert cli.main([command, "--help"]) == 0
    assert f"gauss6 {command}" in capsys.readouterr().out


def test_no_module_imports_the_assembler():
    """cli.py imports the commands; nothing in the package imports cli back (no circle)."""
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        if path.name in ("cli.py", "__main__.py"):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module in ("cli", "gauss6.cli") or (
                    isinstance(node, ast.ImportFrom) and node.module is None and node.level
                    and any(a.name == "cli" for a in node.names)):
                offenders.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert not offenders


def test_exit_codes_table_is_the_codes():
    doc = (paths.REPO_ROOT / "docs" / "cli.md").read_text()
    section = doc.split("## Exit codes", 1)[1]
    rows = re.findall(r"^\| (\d+) \| (.+?) \|$", section, re.M)  # the one table of the section
    assert {int(code): text.strip() for code, text in rows} == cli_args.EXIT_CODES


def test_refusals_return_the_usage_status(capsys):
    assert cli.main(["view", "x.g6trace", "--max-frames", "0"]) == cli_args.EXIT_ERROR  # argparse's refusal
    assert cli.main(["trace", "export", __file__]) == cli_args.EXIT_ERROR  # the error helper's
    assert "gauss6: error: trace export: give --csv DIR" in capsys.readouterr().err
    assert cli.main(["validate", "--bogus"]) == 3  # validate's usage error (validate.EXIT_USAGE)


def test_no_function_over_the_length_bound():
    long = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                start = min([node.lineno] + [d.lineno for d in node.decorator_list])
                if node.end_lineno - start + 1 > MAX_FUNCTION_LINES:
                    long.append(f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name} "
                                f"{node.end_lineno - start + 1} lines")
    assert not long
