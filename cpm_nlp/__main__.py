"""``python -m cpm_nlp``: the cpm-nlp command."""

from .cli.main import main_entry

main_entry()
