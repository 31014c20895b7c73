"""The cell protocol (``Cell``), the ``Builder`` that cells draw their mechanism with, and the
library loader that finds cells in ``stdlib/`` and user directories."""
