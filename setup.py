"""Packaging beyond pyproject.toml: the shipped problem files and solver presets,
and the solver option table (cpm_nlp/core/solver_options.json).

``problems/`` and ``configs/`` stay at the top of the repository; installed, they
are the package data ``cpm_nlp/data/problems`` and ``cpm_nlp/data/configs``
(found by cpm_nlp/problems/shipped.py either way).
"""

from setuptools import find_packages, setup

DATA = {"cpm_nlp.data.problems": "problems", "cpm_nlp.data.configs": "configs"}

setup(
    packages=find_packages(include=["cpm_nlp", "cpm_nlp.*"]) + list(DATA),
    package_dir=DATA,
    package_data={**{name: ["*.yaml", "**/*.yaml"] for name in DATA}, "cpm_nlp.core": ["solver_options.json"]},
)
