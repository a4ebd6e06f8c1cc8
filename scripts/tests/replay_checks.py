"""What the tests of the binaries for other platforms (test_windows.py, test_aarch64.py)
share about fmu_replay's runs."""

from __future__ import annotations

#: The FMUs whose models have states: their columns entry refuses them.
WITH_STATES = {"drive", "motor", "slider_crank_forward", "slider_crank_motor"}


def assert_the_columns_entry_ran_where_algebraic(replays: dict) -> None:
    """Each run compared the FMU's batch evaluation (dyadfmu_evaluate_columns: a
    mechanism's lanes) over the steps' rows too, on every FMU but those with states."""
    for fmu, d in replays.items():
        algebraic = fmu.rsplit("_fmi", 1)[0] not in WITH_STATES
        assert (d.samples == d.steps) == algebraic, (fmu, d.samples, d.steps)
