"""Package data of an installed cpm_nlp: ``problems/`` and ``configs/`` of the
repository, copied here by the build (setup.py); see cpm_nlp/problems/shipped.py."""
