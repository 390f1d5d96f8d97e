"""The library's logger: ``logging.getLogger("speedplan")``, silent unless configured.

speedplan logs at ``DEBUG`` level only (files read and written, batch jobs refused or failed,
solver steps); it attaches a `logging.NullHandler`, so nothing is printed unless the
application configures logging, e.g. ``logging.basicConfig(level=logging.DEBUG)`` or the
command line's ``--verbose``.

Examples
--------
>>> import logging
>>> from speedplan.core.log import logger
>>> logger is logging.getLogger("speedplan")
True
"""

from __future__ import annotations

import logging

__all__ = ["logger"]

logger = logging.getLogger("speedplan")
logger.addHandler(logging.NullHandler())
