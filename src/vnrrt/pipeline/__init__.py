"""The pipeline: one module per DVC stage or stage family (``stages/<stage>.py`` calls one
function of it), and the entry points around the stages (``params``, ``multirun``,
``recompute``, ``variants``, the GPU lease job in :mod:`.gpu`). The only layer that imports
:mod:`vnrrt.viz` and :mod:`vnrrt.studies` together with the library; nothing imports it."""
