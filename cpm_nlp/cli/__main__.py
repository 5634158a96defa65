"""``python -m cpm_nlp.cli``: the cpm-nlp command."""

from .main import main_entry

main_entry()
