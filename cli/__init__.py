"""The command line (``rawehelix``), the demo and the splitting of argv: a thin
layer above the API (:mod:`rawehelix.api`) and the studies; nothing below imports it."""
