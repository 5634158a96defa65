"""Reading YAML input files: see :mod:`cpm_nlp.io.yamlfile` (shared with mechanism files)."""

from ..io.yamlfile import load_yaml_text, read_yaml

__all__ = ["load_yaml_text", "read_yaml"]
