"""Numba CPU kernels: pure functions of arrays, no checks, no objects.

Layout expected by every kernel (the drivers in ``peridyn.physics.materials`` and
``peridyn.solvers`` normalise inputs once):

- ``x, u, f``: (n_points, 3) C-contiguous, float64 or float32 (all the same);
- ``offsets``: (n_points + 1,) int64; ``nbr``: (n_bonds,) int32 (CSR families);
- per-bond arrays (n_bonds,) and per-point arrays (n_points,) of the float dtype;
- ``intact``: (n_bonds,) bool.

The force and dilatation kernels of ``pmb`` and ``lps`` take optional row bounds
``first=0, stop=-1``: they compute the rows ``first .. stop - 1`` (``stop`` < 0: to the last
row) and leave the other rows of their output as they were. An MPI rank computes its rows
clear of the ghosts, then the others once the ghosts have arrived (``force_overlapped`` of
``peridyn.physics.materials``).

``peridyn.kernels.reference`` (one module per kernel module) holds a plain NumPy version of
every kernel, written from its definition; ``tests/kernels`` compares each kernel with it on
small random inputs. Those tests carry the pytest marker ``kernels`` and are run a second
time with the JIT off (the kernels then run as plain Python, which also gives coverage
and a debugger):
``NUMBA_DISABLE_JIT=1 PYTHONPATH=src python -m pytest -m kernels -q -p no:cacheprovider``.

How the force kernels are written (what makes them fast, see ``benchmarks/HISTORY.md``, "What made the
difference" and the later kernel sections; current rates in ``benchmarks/RESULTS.md``):

- the family of point ``i`` is taken in chunks of ``CHUNK`` bonds, each as slices
  ``nbr[c:c + m]``, ``k[c:c + m]``... indexed from 0, and the neighbour index is read as
  unsigned, so that numba emits no negative-index wraparound code and LLVM sees
  unit-stride per-bond loads;
- each chunk takes two loops. The first computes each bond's scalar force (or dilatation
  term) and its ``Y`` and writes them to a small buffer on the stack
  (:func:`stack_array`); it has no sum, so LLVM vectorises it (gathers of the
  neighbours' coordinates, packed square roots and divisions). The second adds the
  chunk's terms to the point's sums one bond after the other, in the written order. A
  single loop would not vectorise: without the "reassoc" flag (see ``FASTMATH``) LLVM
  keeps a sum's order, and it only vectorises a sum it may reorder; the bond loop then
  ran at the scalar divider's rate. Both loops round exactly as the single loop did
  (same operations, same order: the same bits);
- ``x`` and ``u`` are read through flat views (``x.reshape(3 n)``), so the address
  of ``x[j, a]`` is ``3 j + a`` with a compile-time stride;
- broken bonds are masked by a select on ``intact`` (no branch in the loop);
- every constant has the kernel's dtype (``f.dtype.type(...)``): a Python ``0 * r`` or
  ``1 / r`` turns a float32 kernel into float64 arithmetic;
- the bond vector differences come from :func:`bond_differences`, compiled without
  fast-math, so ``Y_ij = -Y_ji`` holds exactly whatever the optimiser does with the rest;
- the float64 force kernels read each bond's reference vector ``xi = x_j - x_i`` from a
  stored (n_bonds, 3) array (``bond_search.initial_bond_vectors``, the same subtraction, so
  the same bits) and gather only ``u_j``: three gathers a bond instead of six, which is
  what the force loop waits on (1.16-1.20x on AMD Zen 4, ``benchmarks/HISTORY.md``, "Stored bond
  vectors, the fused LPS force, ..."). The deformed vector is :func:`deformed_component`, also
  exact;
- the PMB float64 force of a whole body computes each bond pair once and adds it to both
  ends (``pmb.pmb_pair_force``; per pair it streams 53 bytes where the full list streams
  2 x 45), row block by row block so that every sum keeps an order that the full-list kernel
  follows too (``peridyn.discretization.pairs``): the two give the same bits.

Two forms of the stretch are used:

- float64, "length form": ``|Y| - |xi|`` with ``|xi|`` (or ``1 / |xi|``) read from a
  stored per-bond array, as in the reference;
- float32, "cancellation-free form" (kernels named ``*_cf``): ``|xi|`` is recomputed from
  ``x`` and the extension is ``|Y| - |xi| = du . (Y + xi) / (|Y| + |xi|)``,
  ``du = u_j - u_i``, which has no cancellation: in float32 ``|Y| - |xi|`` loses
  everything below ~1e-7 |xi| (strain 1e-6 waves would be noise), and the float32
  rounding of ``x`` (~1e-6 of a millimetre bond) would otherwise show up as a strain.
  It also reads one per-bond float fewer.
"""

import numba
import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, overload

#: Bonds per chunk of the force kernels' two-loop form (see above); the stack buffer of a
#: kernel holds 4 values per bond of a chunk (``CHUNK_BUFFER``). 32 bonds give the vector loop
#: four independent 8-lane iterations to overlap with each other and with the previous chunk's
#: sums; 16 gave it two (our reading of timings, this VM has no hardware counters). Measured
#: (``benchmarks/HISTORY.md``, "Chunks of 32, ..."): PMB float64 1.06-1.07x over 16, float32 1.15x, LPS
#: 1.04-1.07x; 24, 48 and 64 in between or below. The chunk size does not change the bits.
CHUNK = 32
CHUNK_BUFFER = 4 * CHUNK

#: Fast-math flags of the force kernels: "nsz" only (the sign of a zero result may differ). No
#: other flag may change a value, so every compiled kernel performs the IEEE operations of its
#: source in the written order, and the bits of a result do not depend on the instructions
#: numba picks for the CPU at hand (SSE2, AVX2, AVX-512; vectorised or scalar; a kernel compiled
#: afresh or loaded from numba's on-disk cache). Two code paths that perform the same operations
#: in the same order (fused and two-pass LPS, half and full PMB lists, row bounds, MPI ranks,
#: restarts) therefore give the same bits on every x86-64 CPU. Left out on purpose:
#:
#: - "contract" (fused multiply-adds): LLVM fuses a product into a sum where it sees fit, and
#:   what it sees depends on the target and on the code around the sum: on AVX2 targets a
#:   kernel loaded from the cache rounded unlike the same kernel compiled afresh, and the fused
#:   LPS force unlike its two passes;
#: - "arcp" (reciprocals): lets LLVM replace a division or an inverse square root by a
#:   reciprocal (an estimate and a Newton step where the target has one): a float32 kernel's
#:   vectorised and scalar loops rounded differently under it (``lps_pair_force_cf``);
#: - "reassoc": reorders sums (and rounded differently after the cache's second optimisation).
#:
#: Without them the force kernels run within 4 % of their earlier speed (``benchmarks/RESULTS.md``,
#: ``benchmarks/kernel_fastmath.py``). numba's cache does not notice a change here (see
#: ``bond_differences``).
FASTMATH = {"nsz"}


def exact_helper(signature: str):
    """Compile a helper of the fast-math kernels now, without fast-math, for float64 and float32.

    ``signature`` is a format string with ``{t}`` for the float type, e.g. ``"{t}({t}, {t})"``. A helper
    compiled lazily takes the fast-math flags of the first kernel that calls it, and keeps
    them for every later call and in numba's on-disk cache: its roundings would depend on
    which function happened to be compiled first (observed: fused multiply-adds in
    ``squared_length`` after a cold cache). Compiled eagerly for both float types, it has its
    own flags whatever calls it.
    """
    types = [signature.format(t=t) for t in ("float64", "float32")]
    return numba.njit(types, cache=True)


@exact_helper("UniTuple({t}, 3)({t}, {t}, {t}, {t})")
def bond_differences(xj, xi, uj, ui):
    """One component of a bond: ``(xi_a, du_a, Y_a)`` = ``(xj - xi, uj - ui, xi_a + du_a)``.

    Compiled without fast-math (``exact_helper``): LLVM inlines it into the fast-math kernels
    but keeps these three roundings as written, so swapping i and j negates all three exactly
    (Newton's third law to the last bit) and ``du`` keeps its full precision next to
    the much larger coordinates.

    numba's on-disk cache of a kernel does not notice edits to this function, nor to
    ``FASTMATH``: it is keyed on a hash of the kernel's own file. After changing either,
    delete the cached kernels (``find src/peridyn -name '*.nb[ic]' -delete``).
    """
    d = xj - xi
    du = uj - ui
    return d, du, d + du


@exact_helper("{t}({t}, {t}, {t})")
def deformed_component(xi, uj, ui):
    """One component of a bond's deformed vector from its stored reference one:
    ``Y_a = xi_a + (uj - ui)``.

    Compiled without fast-math (``exact_helper``), like :func:`bond_differences`: with ``xi``
    = ``xj - xi`` rounded as there, it returns the same bits as the third value of
    ``bond_differences(xj, xi, uj, ui)``, and swapping the ends negates it exactly.
    """
    return xi + (uj - ui)


def stack_array(size, dtype):
    """A scratch array of ``size`` (a literal int) items of ``dtype``: on the calling kernel's stack.

    LLVM knows that such a buffer (an ``alloca``) shares no memory with the kernel's array
    arguments, so a loop that gathers from those and writes here still vectorises; a
    NumPy array, even one allocated inside the kernel, is opaque to it and blocks the
    vectorisation. Allocated once per call of the compiled loop body, whatever the number
    of iterations; it lives until the kernel returns. With the JIT off (``NUMBA_DISABLE_JIT``)
    this plain function runs instead: a NumPy array. As with :func:`bond_differences`, numba's
    on-disk cache of a kernel does not notice edits here: delete the cached kernels after one.
    """
    return np.empty(size, dtype)


@intrinsic
def _stack_pointer(typingctx, size, dtype):
    """Pointer to ``size`` (literal) items of ``dtype`` in the caller's stack frame."""
    if not isinstance(size, types.IntegerLiteral):
        return None
    n = size.literal_value

    def codegen(context, builder, signature, args):
        ptr = cgutils.alloca_once(builder, context.get_value_type(dtype.dtype), size=n)
        ptr.align = 64  # one cache line: the vector loop's stores then never split across two
        return ptr

    return types.CPointer(dtype.dtype)(size, dtype), codegen


@overload(stack_array, prefer_literal=True)
def _stack_array_jit(size, dtype):
    if not isinstance(size, types.IntegerLiteral):
        return None

    def impl(size, dtype):
        return numba.carray(_stack_pointer(size, dtype), size)

    return impl
