"""The seed Lamb plate cut to 60 x 39.6 mm with every kind of probe (sensors at the top, middle
and under the actuator, a line along x, the top plane, a PZT sensor): the ``--set`` overrides the
MPI run tests share (tests/mpi/test_mpi_runs.py on bond lists, test_mpi_lattice.py on lattice
storage), each adding its own end time and snapshot."""

LAMB_PROBES = [
    "geometry.size=[0.06, 0.0396, 0.002]",
    "actuators.pzt.center=[0.0306, 0.0198]",
    "output.sensors={top: [0.0426, 0.0198, 0.002], mid: [0.0426, 0.0198, 0.001], "
    "centre: [0.0306, 0.0198, 0.002]}",
    "output.lines={x_axis: {start: [0.0006, 0.0198, 0.002], end: [0.0594, 0.0198, 0.002], points: 50}}",
    "output.pzt_sensors={p: {center: [0.0426, 0.0198], size: 2.4e-3}}",
    "analysis={}",
]
