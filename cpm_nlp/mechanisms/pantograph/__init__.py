"""3D compliant pantograph, decoupled XYZ (Elgammal, Fanni, Mohamed 2016): the add-on of its
mechanism file problems/mechanisms/pantograph.yaml (issue 21, item 5).

* `addon` -- `ADDON`, what the file cannot say;
* `analysis` -- the paper's limits (eq 31), closed-form workspace (eq 17-29) and cuboid
  (eq 32-34), on the file's model;
* `synthesis` -- its dimensional synthesis (eq 35-38).

The hand-written loop closures this package held until issue 21 are the independent
reference tests/reference/pantograph_closures.py.
"""
