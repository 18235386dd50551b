# Type stubs of the native module sdfc._sdfc (python/src/lib.rs); python/sdfc/__init__.py is
# the API users call, with its own annotations.
from typing import Any, Dict, List, Optional, Sequence, Tuple

class CompileError(Exception):
    diagnostics: List[Any]

def check(source: Optional[str] = ..., path: Optional[str] = ..., limits: Sequence[str] = ...) -> Tuple[List[Dict[str, Any]], Optional[Dict[str, Any]]]: ...
def builtins() -> List[Dict[str, Any]]: ...
def records() -> List[Dict[str, Any]]: ...
def range_error(owner: str, sig: int, index: int, value: Any) -> Optional[str]: ...
def fmt(text: str) -> Optional[str]: ...

class _Scene:
    def __init__(self, source: Optional[str] = ..., path: Optional[str] = ..., set: Sequence[str] = ..., limits: Sequence[str] = ..., params: Sequence[Tuple[str, str]] = ...) -> None: ...
    def info(self) -> Dict[str, Any]: ...
    def params(self) -> List[Dict[str, Any]]: ...
    def render(
        self,
        size: Optional[Tuple[int, int]] = ...,
        backend: str = ...,
        aa: Optional[int] = ...,
        t: float = ...,
        encoding: str = ...,
    ) -> Tuple[int, int, bytes]: ...
    def depth(
        self,
        size: Optional[Tuple[int, int]] = ...,
        backend: str = ...,
        aa: Optional[int] = ...,
        t: float = ...,
    ) -> Tuple[int, int, bytes, bytes]: ...
    def distance(self, points: bytes, t: float = ..., backend: str = ...) -> Tuple[bytes, bytes]: ...
    def mesh(
        self,
        resolution: Optional[int] = ...,
        voxel: Optional[float] = ...,
        bounds: Optional[Tuple[Tuple[float, float, float], Tuple[float, float, float]]] = ...,
        sharp: bool = ...,
        t: float = ...,
    ) -> Tuple[bytes, bytes, bytes]: ...
    def save(
        self,
        path: str,
        resolution: Optional[int] = ...,
        voxel: Optional[float] = ...,
        bounds: Optional[Tuple[Tuple[float, float, float], Tuple[float, float, float]]] = ...,
        sharp: bool = ...,
        t: float = ...,
        up: Optional[str] = ...,
    ) -> Tuple[int, int]: ...
    def compile(self, emit: str, part: str = ..., name: Optional[str] = ..., sm: int = ..., t: float = ...) -> bytes: ...
