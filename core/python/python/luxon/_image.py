"""The array a render returns: a numpy array that Jupyter shows as a picture."""

import numpy as np

from . import _luxon


class Image(np.ndarray):
    """A rendered image: a ``numpy.ndarray`` of shape ``(height, width, 4)``, RGBA, either
    ``uint8`` (sRGB, as a PNG holds it) or ``float32`` (linear). Everything numpy does works on
    it; in Jupyter (IPython) it displays itself as a PNG.
    """

    def _repr_png_(self):
        if self.ndim != 3 or self.shape[2] != 4 or self.dtype not in (np.uint8, np.float32):
            return None
        return _luxon.encode_png(np.ascontiguousarray(self).view(np.ndarray))

    def save(self, path, context=None):
        """Writes the image to ``path`` with the writer plugin its extension names
        (``.png``, ``.exr``, ``.ppm``...); see :func:`luxon.write_image`."""
        from . import write_image

        write_image(path, self, context=context)
