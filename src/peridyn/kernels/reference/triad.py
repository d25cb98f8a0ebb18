"""Reference of ``peridyn.kernels.triad``: the STREAM triad."""


def triad(b, c, s):
    """``b + s c`` (elementwise; one product and one sum, each rounded, in the inputs' dtype)."""
    return b + s * c
