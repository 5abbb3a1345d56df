"""Files at the edges, and model loading. The model layers below never read files.

- :mod:`~kinestat.io.library` — ``load``/``list_models`` (embedded models or TOML files) and the
  embedded 2011 prototype platform (:func:`~kinestat.io.library.prototype`).
- :mod:`~kinestat.io.model_toml` — TOML model files (read, write, round trip).
- :mod:`~kinestat.io.platform_toml` — TOML platform files.
- :mod:`~kinestat.io.axes_file` — axes files (joint axes in the world frame, for dh-from-axes).
- :mod:`~kinestat.io.urdf` — URDF export and import of serial chains.
- :mod:`~kinestat.io.posefile` — pose files (JSON, TOML or plain numbers).
- :mod:`~kinestat.io.disp_deck` — DISP card decks (Nadkarni 1977).
- :mod:`~kinestat.io.textfile` — the text reader and atomic writer every format uses.
- :mod:`~kinestat.io.jsonable` — numpy results to JSON-ready values.
- ``kinestat.io._fields`` — checked fields of parsed TOML/JSON documents (private).
"""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'axes_file': ['loads_axes', 'read_axes_file'],
        'disp_deck': [
            'DeckJoint', 'DispDeck', 'OperatorCommand', 'deck_warnings', 'embedded_deck',
            'list_embedded_decks', 'parse_deck', 'read_deck', 'write_deck',
        ],
        'library': ['list_models', 'load', 'prototype'],
        'model_toml': ['dumps_model', 'loads_model', 'read_model', 'write_model'],
        'platform_toml': ['PlatformMount', 'dumps_platform', 'loads_platform', 'read_platform',
                          'read_mount_file', 'read_platform_mount', 'write_platform'],
        'posefile': ['read_pose_file'],
        'urdf': ['from_urdf', 'read_urdf', 'to_urdf'],
    },
)
