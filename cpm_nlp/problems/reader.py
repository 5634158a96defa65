"""Reading YAML input files: see `cpm_nlp.io.yamlfile` (shared with mechanism files)."""

from ..io.yamlfile import MAX_ALIASES, MAX_DEPTH, MAX_NODES, load_yaml_text, parse_yaml, read_yaml

__all__ = ["MAX_ALIASES", "MAX_DEPTH", "MAX_NODES", "load_yaml_text", "parse_yaml", "read_yaml"]
