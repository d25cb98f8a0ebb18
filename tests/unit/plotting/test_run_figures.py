"""Figures a newcomer reads at once: the B-scan's three components on one colour scale with a
colour bar, each sensor labelled with its position, rigid modes reported as 0 Hz."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import small_model

from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.results import Results
from peridyn.jobs.modal import modal_table
from peridyn.plotting import fields


@pytest.fixture
def drawn(monkeypatch):
    """The figures the plotting functions save, kept open for inspection."""
    figures = []

    def keep(fig, path):
        figures.append(fig)
        return path

    monkeypatch.setattr(fields, "_save", keep)
    yield figures
    for fig in figures:
        fields.plt.close(fig)


@pytest.fixture
def results(tmp_path):
    """A results file with 3 sensors and a 4-point line whose x component is 10 times its z."""
    points = np.column_stack([np.arange(4) * 1e-3, np.full(4, 2e-3), np.full(4, 1e-3)])
    with HDF5Writer(tmp_path / "results.h5", points, np.full(4, 1e-9), {}) as out:
        out.create_series("sensor_u", (3, 3), attrs={"names": ["a", "b", "c"], "points": [0, 2, 3]})
        out.create_series("line_axis", (4, 3), attrs={"points": [0, 1, 2, 3]})
        for step in range(5):
            u = np.zeros((4, 3))
            u[:, 0], u[:, 2] = 1e-6 * np.sin(step + np.arange(4)), 1e-7 * np.cos(step + np.arange(4))
            out.append("sensor_u", step, step * 1e-7, u[[0, 2, 3]])
            out.append("line_axis", step, step * 1e-7, u)
    return Results(tmp_path / "results.h5")


def test_bscan_components_share_one_scale_and_a_colour_bar(results, drawn, tmp_path):
    fields.plot_bscan(results, "axis", tmp_path / "bscan.png")
    (fig,) = drawn
    images = [im for ax in fig.axes for im in ax.get_images()]
    assert len(images) == 3 and len(fig.axes) == 4  # three panels and their colour bar
    largest = np.abs(results.series("line_axis")[2]).max()
    assert {im.get_clim() for im in images} == {(-largest, largest)}
    assert fig.axes[3].get_ylabel() == "displacement (m)"


def test_sensor_labels_give_their_positions_in_mm(results, drawn, tmp_path):
    fields.plot_sensors(results, tmp_path / "sensors.png")
    (fig,) = drawn
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["a\n(0, 2, 1) mm\nu (m)", "b\n(2, 2, 1) mm\nu (m)", "c\n(3, 2, 1) mm\nu (m)"]


def test_rigid_modes_are_reported_at_0_hz():
    """A free cube: its six rigid modes come out of the solver at round-off frequencies of
    either sign; their rows say 0 Hz, the elastic rows keep the solver's frequency."""
    result, _, rows = modal_table(small_model("lps", n=6), 8)
    assert result.rigid.sum() == 6
    assert [row["frequency_hz"] for row in rows[:6]] == [0.0] * 6
    assert [row["frequency_hz"] for row in rows[6:]] == [float(f) for f in result.frequencies[6:]]
    assert all(row["frequency_hz"] > 1e3 for row in rows[6:])


def test_sweep_figure_axes_carry_the_units(monkeypatch, tmp_path):
    """A sweep figure labels its axes with the dataset's units (Pa, J) and its legend the other
    parameter's value with its unit."""
    from matplotlib.figure import Figure

    from peridyn.io.dataset import build_dataset
    from peridyn.plotting import sweep

    drawn = []

    class Kept(Figure):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            drawn.append(self)

    monkeypatch.setattr(sweep, "Figure", Kept)
    ds = build_dataset(
        {
            "run_id": ["a", "b", "c", "d"],
            "material.E": [1e9, 2e9, 1e9, 2e9],
            "material.density": [1e3, 1e3, 2e3, 2e3],
        },
        {"strain_energy_j": [1.0, 2.0, 3.0, 4.0]},
        {},
        {},
        about={
            "material.E": ("Pa", "E"),
            "material.density": ("kg/m^3", "rho"),
            "strain_energy_j": ("J", "W"),
        },
    )
    sweep.plot_against(ds, "material.E", "strain_energy_j", ["material.density"], tmp_path / "w.png")
    (ax,) = drawn[0].axes
    assert ax.get_xlabel() == "material.E (Pa)" and ax.get_ylabel() == "strain_energy_j (J)"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "material.density = 1000 kg/m^3",
        "material.density = 2000 kg/m^3",
    ]
