"""The one error family Tessera raises; messages are written for the user who has to act on them."""


class TesseraError(Exception):
    """Base class: an operator reports ``str(err)`` and leaves the scene unchanged."""


class InvalidInputError(TesseraError):
    """The input mesh, levels or parameters cannot be processed as given."""


class BudgetError(TesseraError):
    """The estimated output is larger than the configured memory budget."""


class OpenCLUnavailableError(TesseraError):
    """OpenCL was required (``TESSERA_OPENCL=require``) but no usable platform was found."""


class GPUContextError(TesseraError):
    """No GPU context could be created (background mode without EGL/Mesa or a GPU)."""


class GPUShaderError(TesseraError):
    """A shader did not compile on this GPU backend (remembered: it is not compiled again in this session)."""


class EmptyResultError(TesseraError):
    """The input is valid but gives nothing to make (curves without length, a terrain the camera does not see);
    the message says what to change."""
