"""3-PRC micromanipulator with secondary lever amplifiers (Li, Li, Ding, Xu 2018): the
add-on of its mechanism file problems/mechanisms/prc3.yaml (issue 21, item 5).

* `addon` -- `ADDON`, what the file cannot say;
* `dynamics` -- the Lagrange model (eq 28-41) on the file's closures;
* `kinds` -- its own problem kind ``amplifier`` (eq 1-2).

The hand-written loop closures this package held until issue 21 are the independent
reference tests/reference/prc3_closures.py.
"""
