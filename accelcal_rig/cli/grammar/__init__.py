"""The `rig` command line's grammar, one module per group of commands; `cli_parser.build_parser` puts them
together in the order `rig --help` lists them.

Parsing imports nothing heavy: `rig --help` and a mistyped option answer at once.
"""
