"""The confirmatory studies (a plan committed before its data, then one test per hypothesis over independent draws),
in one folder: :mod:`.numbers` (the tests over draws, Holm, TOST, power and coverage, the exchange rate on the
real-shape curve), :mod:`.tables` (a plan's folder: reading and checking the plan, adding a draw's tables, combining
them into the plan's result, the plan's git history), :mod:`.words` (the figures the README and docs quote)."""
