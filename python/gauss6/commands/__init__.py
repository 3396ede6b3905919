"""The `gauss6` subcommands, one module a command, each with the same two functions:

    add_parser(subparsers) -> argparse.ArgumentParser   the command's parser (its options,
                                                         its sub-actions if any), returned
    run(args) -> int                                     the command: its exit status

gauss6.cli assembles them (COMMANDS, in help order) and calls `run`; a module here imports
its argument types and its error helper from gauss6.cli_args, and the library modules it
drives only inside `run`, so that building the parser stays cheap. docs/cli.md states the
convention and the exit codes.
"""
