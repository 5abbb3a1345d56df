"""Numba's cached kernels loaded without parsing their LLVM bitcode until another kernel links it.

A kernel in Numba's disk cache holds its machine code (an object file) and its LLVM bitcode.
Numba needs the bitcode only to link the kernel into another kernel being compiled. To load the
kernel it also reads the bitcode, to learn which symbols the kernel defines. Parsing the
bitcode is most of a load: about 4 ms for a closed-form single-pose kernel, the largest step of
a first ``ik_all`` call. The library class installed here reads the defined symbols from the
object file's symbol table instead (ELF: a few hundred bytes, about 0.1 ms) and parses the
bitcode the first time a kernel being compiled links it. Everything else is Numba's: what the
cache holds, where it lives, how the machine code is loaded.

Only 64-bit little-endian ELF object files (Linux x86-64 and AArch64) take this path; any other
object file, or a symbol table that cannot be read, is loaded by Numba's own code.
:func:`install` puts the class in place once per process (Numba reads the library class each
time it creates or loads a kernel), on the Numba releases it was checked against; other releases
keep Numba's own load.
"""

from __future__ import annotations

import struct

import numba
from llvmlite import binding as ll
from numba.core import codegen

__all__ = ["CHECKED_NUMBA", "LazyLinkLibrary", "defined_symbols", "install"]

_ELF64_LE = b"\x7fELF\x02\x01"
_SHT_SYMTAB = 2
_SHN_UNDEF = 0
_STT_SECTION, _STT_FILE = 3, 4


def defined_symbols(obj: bytes) -> set[str] | None:
    """The names of the symbols a 64-bit little-endian ELF object file defines (functions and
    data, every binding), or None when ``obj`` is not one or has no readable symbol table."""
    if obj[:6] != _ELF64_LE:
        return None
    try:
        shoff, = struct.unpack_from("<Q", obj, 0x28)
        shentsize, shnum = struct.unpack_from("<HH", obj, 0x3A)
        for i in range(shnum):
            sh = shoff + i * shentsize
            sh_type, = struct.unpack_from("<I", obj, sh + 4)
            if sh_type != _SHT_SYMTAB:
                continue
            off, size, link, _, _, entsize = struct.unpack_from("<QQIIQQ", obj, sh + 0x18)
            str_off, = struct.unpack_from("<Q", obj, shoff + link * shentsize + 0x18)
            names = set()
            for s in range(off + entsize, off + size, entsize):  # entry 0 is the null symbol
                name, info, _, shndx = struct.unpack_from("<IBBH", obj, s)
                if shndx == _SHN_UNDEF or (info & 0xF) in (_STT_SECTION, _STT_FILE) or not name:
                    continue
                end = obj.index(b"\0", str_off + name)
                names.add(obj[str_off + name:end].decode())
            return names
    except (struct.error, ValueError, UnicodeDecodeError):
        return None
    return None


class LazyLinkLibrary(codegen.JITCodeLibrary):
    """Numba's JIT code library whose cached bitcode is parsed on first link, not on load."""

    _shared_bitcode: bytes | None = None

    def _get_module_for_linking(self):
        if self._shared_module is None and self._shared_bitcode is not None:
            self._shared_module = ll.parse_bitcode(self._shared_bitcode)
            self._shared_bitcode = None
        return super()._get_module_for_linking()

    @classmethod
    def _unserialize(cls, codegen_, state):
        name, kind, data = state
        names = defined_symbols(data[0]) if kind == "object" else None
        if names is None:
            return super()._unserialize(codegen_, state)
        object_code, shared_bitcode = data
        self = codegen_.create_library(name)
        self.enable_object_caching()
        self._set_compiled_object(object_code)
        self._shared_bitcode = shared_bitcode
        self._finalize_final_module()
        codegen_._engine._defined_symbols |= names
        return self


#: Numba releases whose library class this module was checked against (the class overrides two
#: of its private methods); any other release keeps Numba's own load
CHECKED_NUMBA = ("0.68",)


def install() -> None:
    """Make Numba's CPU code generator create and load :class:`LazyLinkLibrary` libraries (on the
    Numba releases of :data:`CHECKED_NUMBA` only)."""
    if not numba.__version__.startswith(CHECKED_NUMBA):
        return
    if codegen.JITCPUCodegen._library_class is codegen.JITCodeLibrary:
        codegen.JITCPUCodegen._library_class = LazyLinkLibrary
