"""stackplan: stacking plans and contact states of polyhedral sheet-metal parts.

Python bindings of the Rust crates (Ayyadevara et al. 2002, Pan & Schimmels 2004). Lengths are in millimetres,
angles in degrees (keyword arguments ending in ``_deg``). Keyword options are those of the ``stackplan`` command line
without the leading ``--`` and with ``_`` for ``-``, with the same defaults, checks and one-line error messages.
Every error is a :class:`StackplanError` (a ``ValueError``). Long calls release the GIL and can be interrupted with
Ctrl-C. See ``docs/python.md``.
"""

from ._native import Part, Plan, Report, StackplanError, check, contacts, cspace_obstacle, place, plan

__all__ = ["Part", "Plan", "Report", "StackplanError", "check", "contacts", "cspace_obstacle", "place", "plan"]
