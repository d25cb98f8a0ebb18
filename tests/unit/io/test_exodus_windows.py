"""The steps at which an Exodus file gets a record (``RecorderSpec.exodus_due``): every
``every``-th step within its window of ``first_step`` to ``last_step``, as Peridigm's
``Output Frequency``, ``Initial Output Step`` and ``Final Output Step`` select them."""

from peridyn.io.recorder import RecorderSpec


def test_files_are_written_within_their_step_windows():
    """Peridigm's Compression_QS_Explicit_MultiFreqOutput test: Output1 every step up to step 20
    (t = 0 and the 20 load steps), Output2 every 100th step from step 21 on; its gold file
    holds 21 records of the first and steps 100 to 500 of the second."""
    more = {"exodus_every": 100, "exodus_first": 21, "exodus_last": None}
    spec = RecorderSpec(exodus=True, exodus_named=True, exodus_every=1, exodus_last=20, exodus_more=(more,))
    steps = range(0, 522)
    assert [k for k in steps if spec.main_exodus_due(k)] == list(range(21))
    assert [k for k in steps if spec.exodus_due(k) and not spec.main_exodus_due(k)] == [
        100,
        200,
        300,
        400,
        500,
    ]


def test_a_file_without_a_window_is_written_from_step_0():
    """Without a window, every ``every``-th step from step 0 (as before windows existed)."""
    spec = RecorderSpec(exodus=True, exodus_named=True, exodus_every=3)
    assert [k for k in range(10) if spec.exodus_due(k)] == [0, 3, 6, 9]
