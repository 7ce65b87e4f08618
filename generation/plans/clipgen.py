"""Turn a validated plan entry into a Motion with its registered generator (generation.plans.generators).

The optional network generators (gesture_net, rbf, neutral_walk) import their networks inside ``make``, so a
missing or broken network fails only the entries that use it, with a message naming the entry
(:class:`ClipGenerationError`; :func:`availability` says why beforehand). gait_net names its weights through
``generation.gait.weights``, whose package loads torch, so planning loads torch.

A network generator whose weights are not there yet may be replaced by the entry's ``fallback``
(procedural_walk for gait_net, procedural_gesture for gesture_net). The clip is then recorded with the
generator that really made it, ``metadata["fallback_for"]`` and ``synthetic: True``; it is never passed off
as the network's output. Its content hash differs, so once the weights exist the clip is rendered anew.
"""
from __future__ import annotations

import ast
import functools
import hashlib
import importlib
import importlib.util
from pathlib import Path

from generation.core.digest import cached_file_sha256
from generation.core.motion import Motion
from generation.formats.bvh import write_bvh

from .generators import ClipGenerationError, MakeContext, PlanInputs, get_generator
from .schema import ClipEntry

__all__ = ["ClipGenerationError", "availability", "fallback_entry", "generator_version", "make_motion", "resolve",
           "source_digest", "source_files", "write_motion_bvh"]


def _weights_file(generator: str, inputs: PlanInputs | None) -> Path | None:
    weights = get_generator(generator).weights
    return None if weights is None else weights(inputs)


def availability(generator: str, inputs: PlanInputs | None = None) -> str | None:
    """None when ``generator`` can run here (for ``inputs``: their weights), else the reason it cannot (a module
    that does not import, a missing weights file)."""
    for mod in get_generator(generator).requires:
        try:
            importlib.import_module(mod)
        except Exception as exc:  # noqa: BLE001 - any import failure makes the generator unavailable
            return f"module {mod} cannot be imported ({type(exc).__name__}: {exc})"
    weights = _weights_file(generator, inputs)
    if weights is not None and not weights.is_file():
        return f"weights file {weights} is missing"
    return None


PACKAGE_DIR = Path(__file__).resolve().parent.parent
#: The shared study protocol package (vocabularies); generators that import it depend on it too.
PROTOCOL_PACKAGE = "protocol"


def _imported_files(path: Path) -> set[Path]:
    """Project source files a module imports (relative ``from .x`` and absolute ``generation.x`` imports,
    including imports inside functions)."""
    out: set[Path] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level:
            base = path.parent
            for _ in range(node.level - 1):
                base = base.parent
            parts = node.module.split(".") if node.module else []
        elif node.module and node.module.split(".")[0] == "generation":
            base, parts = PACKAGE_DIR, node.module.split(".")[1:]
        elif node.module and node.module.split(".")[0] == PROTOCOL_PACKAGE:
            base, parts = PACKAGE_DIR.parent, node.module.split(".")
        else:
            continue
        target = base.joinpath(*parts)
        candidates = [target.with_suffix(".py"), target / "__init__.py"]
        candidates += [target / f"{a.name}.py" for a in node.names]
        out.update(c.resolve() for c in candidates if c.is_file())
    return out


def _module_file(module: str) -> Path:
    """The source file of a module, found without importing it (its parent packages are imported)."""
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        raise ClipGenerationError(f"module {module} not found")
    return Path(spec.origin)


def source_files(generator: str) -> list[Path]:
    """The files whose content a generator's output depends on: the module that declares it, its required modules
    and everything they import from the project (followed transitively), this file, and the small data files
    under ``generation/data`` (weights apart; they have their own digest). A data folder named after a package of
    ``generation`` (``data/rbf``, ``data/mocap``, ...) counts only for generators whose code imports that package,
    so new RBF intensities re-render the RBF clips and leave the gait and gesture networks' clip ids alone; every
    other data file counts for all."""
    spec = get_generator(generator)
    todo = [_module_file(m) for m in (spec.module, *spec.requires)]
    seen: set[Path] = set()
    while todo:
        path = todo.pop().resolve()
        if path in seen or not path.is_file():
            continue
        seen.add(path)
        todo.extend(_imported_files(path) - seen)
    seen.add(Path(__file__).resolve())
    data = PACKAGE_DIR / "data"
    root = PACKAGE_DIR.resolve()
    packages = {d.name for d in root.iterdir() if (d / "__init__.py").is_file()}
    imported = {p.relative_to(root).parts[0] for p in seen if p.is_relative_to(root)}

    def counts(p: Path) -> bool:
        folder = p.relative_to(data).parts[0] if len(p.relative_to(data).parts) > 1 else ""
        return folder not in packages or folder in imported

    return sorted(seen) + sorted(p.resolve() for p in data.rglob("*") if p.is_file() and "weights" not in p.parts
                                 and p.stat().st_size < 5_000_000 and counts(p))


@functools.cache
def source_digest(generator: str) -> str:
    """Digest of :func:`source_files`. It goes into the clip hash, so a change to a generator's code or data
    renders its clips anew instead of reusing stale files."""
    files = source_files(generator)
    h = hashlib.sha256()
    for f in files:
        h.update(str(f.relative_to(PACKAGE_DIR.parent)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:12]


def generator_version(generator: str, inputs: PlanInputs | None = None) -> str:
    """Version string that goes into the clip hash: the declared version, the digest of the generator's source
    code and data (:func:`source_digest`) and, for networks, of the weights file the inputs are made with (None:
    the default weights)."""
    version = f"{get_generator(generator).version}+src{source_digest(generator)}"
    weights = _weights_file(generator, inputs)
    if weights is not None and weights.is_file():
        version += "+w" + cached_file_sha256(weights)[:12]
    return version


def resolve(entry: ClipEntry) -> tuple[ClipEntry, str | None]:
    """The entry as it will be made: itself, or its fallback when the generator is unavailable.

    Returns (entry, reason the requested generator was replaced or None). Raises ClipGenerationError when
    neither the generator nor a fallback can run.
    """
    reason = availability(entry.generator, entry.inputs)
    if reason is None:
        return entry, None
    if entry.fallback is None:
        raise ClipGenerationError(f"{entry.where}: generator {entry.generator!r} is not available: {reason}")
    fb = fallback_entry(entry)
    fb_reason = availability(fb.generator, fb.inputs)
    if fb_reason is not None:
        raise ClipGenerationError(f"{entry.where}: generator {entry.generator!r} is not available ({reason}) "
                                  f"and its fallback {entry.fallback!r} neither ({fb_reason})")
    return fb, f"{entry.generator} unavailable: {reason}"


def fallback_entry(entry: ClipEntry) -> ClipEntry:
    """The entry re-expressed for its fallback generator (inputs mapped by the generator's declaration; the intent
    is unchanged)."""
    convert = get_generator(entry.generator).fallback_inputs
    inputs = entry.inputs if convert is None else convert(entry.inputs, entry.fallback)
    return entry.with_generator(entry.fallback, inputs)


def make_motion(entry: ClipEntry, fps: float | None = None, requested: str | None = None,
                fallback_reason: str | None = None, device: str = "cpu") -> Motion:
    """Generate the motion of a (resolved) entry at ``fps`` (default: the entry's render fps).

    Args:
        entry: a validated entry, after :func:`resolve` (its ``generator`` is the one that runs).
        requested: the generator the plan asked for, when a fallback replaced it.
        fallback_reason: why, for the metadata.
        device: torch device of the network generators ("cpu": the same stimuli as on a machine without a GPU).
    Returns the Motion with metadata naming the entry, the generator that made it, origin and whether it
    is synthetic. ClipGenerationError names the entry when the generator fails.
    """
    spec = get_generator(entry.generator)
    try:
        motion = spec.make(entry, MakeContext(fps or entry.render.fps, device))
    except ClipGenerationError:
        raise
    except Exception as exc:  # noqa: BLE001 - reported with the entry's name, original traceback chained
        raise ClipGenerationError(f"{entry.where}: generator {entry.generator!r} failed: "
                                  f"{type(exc).__name__}: {exc}") from exc
    meta = motion.metadata
    meta.setdefault("synthetic", meta.get("origin") in ("procedural", "generated") and not spec.captured)
    meta["generator_module_origin"] = meta.get("origin")
    meta["origin"] = entry.origin
    meta["generator"] = entry.generator
    meta["entry_id"] = entry.id
    if requested and requested != entry.generator:
        meta["fallback_for"] = requested
        meta["fallback_reason"] = fallback_reason or ""
        meta["synthetic"] = True
    return motion


# ---- motion files ------------------------------------------------------------------------------
def write_motion_bvh(motion: Motion, motions_dir: str | Path, clip_id: str) -> Path:
    """Keep a clip's motion as ``motions_dir/<clip_id>.bvh`` (DESIGN.md: ``MEDIA_ROOT/motions/<clip_id>.bvh``).

    The file appears under its final name only when complete (temporary name, then rename). Like the clip records,
    ``motions_dir`` is never served: a motion file names no condition, but its id is the clip's.
    Returns the path written.
    """
    if not clip_id or any(c in clip_id for c in "/\\.") or clip_id.strip() != clip_id:
        raise ValueError(f"clip id {clip_id!r} cannot name a file")
    motions_dir = Path(motions_dir)
    motions_dir.mkdir(parents=True, exist_ok=True)
    path = motions_dir / f"{clip_id}.bvh"
    tmp = motions_dir / f".{clip_id}.bvh.tmp"
    write_bvh(motion, tmp)
    tmp.replace(path)
    return path
