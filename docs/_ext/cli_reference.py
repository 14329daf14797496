"""The parser of ``symstab`` as sphinx-argparse renders it: the same parser, its text as reST.

sphinx-argparse reads every help text, description and epilog as
reStructuredText.  symstab's texts are written for a terminal: a command whose
``formatter_class`` is ``RawDescriptionHelpFormatter`` lays its epilog out by
hand (a table of quantities), and ``|x|`` is the absolute value, not a
substitution.  :func:`build_parser` returns the parser of
:func:`symstab.cli.commands.build_parser` with those texts made literal: a
description or epilog laid out by hand (indented lines) becomes a literal
block, and ``|`` is escaped.
The words are the command line's own.
"""

import argparse

from symstab.cli.commands import build_parser as _build_parser


def _literal(text):
    lines = text.strip("\n").splitlines()
    return "::\n\n" + "\n".join("    " + line if line else "" for line in lines)


def _escaped(text):
    return text.replace("|", "\\|")


def _adapt(parser):
    raw = issubclass(parser.formatter_class, argparse.RawDescriptionHelpFormatter)
    for attribute in ("description", "epilog"):
        text = getattr(parser, attribute)
        if text:
            laid_out = raw and any(line.startswith(" ") for line in text.splitlines())
            setattr(parser, attribute, _literal(text) if laid_out else _escaped(text))
    for action in parser._actions:
        if action.help and action.help is not argparse.SUPPRESS:
            action.help = _escaped(action.help)
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                if choice.help:
                    choice.help = _escaped(choice.help)
            for sub in {id(p): p for p in action.choices.values()}.values():
                _adapt(sub)


def build_parser():
    """symstab's parser, its texts made literal for reST (see the module's docstring)."""
    parser = _build_parser()
    _adapt(parser)
    return parser
