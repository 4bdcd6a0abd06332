"""Where each table and key of a model's TOML text sits, for the line numbers of messages.

May use: the standard library.
"""
from __future__ import annotations

import re


class _Lines:
    """Where each table and key of a TOML text sits: field path -> line number (best effort:
    tomllib gives no positions, so the text is scanned for table headers and keys)."""

    _HEADER = re.compile(r"\s*(\[\[?)\s*([A-Za-z0-9_\-.\"' ]+?)\s*\]\]?\s*(#.*)?$")   # not a row [x, y],
    _PART = r"""(?:[A-Za-z0-9_\-]+|"[^"]*"|'[^']*')"""
    _KEY = re.compile(rf"\s*({_PART}(?:\s*\.\s*{_PART})*)\s*=")
    _INLINE_KEY = re.compile(r"[{,]\s*([A-Za-z0-9_\-]+|\"[^\"]*\"|'[^']*')\s*=")

    def __init__(self, text: str):
        self.at: dict[tuple, int] = {}
        arrays: dict[tuple, int] = {}         # array-of-tables path -> tables seen so far
        current: tuple = ()
        in_string = False
        for n, line in enumerate(text.splitlines(), 1):
            if (line.count('"""') + line.count("\'\'\'")) % 2:
                in_string = not in_string
                if not in_string:
                    continue
            if in_string:
                continue
            head = self._HEADER.match(line)
            if head:
                parts = self._split(head[2])
                if head[1] == "[[":
                    parts = self._resolve(parts[:-1], arrays) + parts[-1:]
                    arrays[parts] = arrays.get(parts, 0) + 1
                    current = parts + (arrays[parts] - 1,)
                else:
                    current = self._resolve(parts, arrays)
                self.at.setdefault(current, n)
                continue
            key = self._KEY.match(line)
            if key:
                path = current + self._split(key[1])
                self.at.setdefault(path, n)
                for inner in self._INLINE_KEY.findall(line):
                    self.at.setdefault(path + (inner.strip("\"'"),), n)

    @staticmethod
    def _split(key: str) -> tuple:
        return tuple(p.strip().strip("\"'") for p in key.split("."))

    @staticmethod
    def _resolve(parts: tuple, arrays: dict[tuple, int]) -> tuple:
        out: tuple = ()
        for p in parts:
            out += (p,)
            if out in arrays:
                out += (arrays[out] - 1,)
        return out

    def line(self, path: tuple) -> int | None:
        """Line of `path` or of its nearest enclosing table or key."""
        for end in range(len(path), 0, -1):
            if path[:end] in self.at:
                return self.at[path[:end]]
        return None
