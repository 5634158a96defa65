"""RPR compliant mechanism from a 2-RPU-UPR (Zhang, Liu, Ding 2022): the add-on of its
mechanism file problems/mechanisms/rpr.yaml (issue 21, item 5).

* `addon` -- `ADDON`, what the file cannot say;
* `screws` -- the screw-theory Jacobian (eq 7-13) and the displacement twists (eq 45);
* `design` -- transmission index and dimensional synthesis (eq 14-32);
* `compliance` -- the joint design and the pseudo-rigid-body compliance model (eq 27-44),
  on the file's closures;
* `kinds` -- its own problem kinds (``rpr_*``) and its synthesis formulation.

The hand-written loop closures this package held until issue 21 are the independent
reference tests/reference/rpr_closures.py.
"""
