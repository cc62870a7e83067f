"""A minimal 3MF writer for several objects of different materials (3MF Core Specification 1.3, §4 and the
``basematerials`` resource of §5): one ``<object>`` per body, each pointing at its base material, all in the
build, each material with its density when known.  Used by ``spin-it --out part.3mf`` for a hollowed part with a
dense insert."""

from __future__ import annotations

import zipfile

import numpy as np

from ..mesh.threemf import DENSITY_NAMESPACE

__all__ = ["write_3mf"]

_CONTENT_TYPES = """<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
 <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
 <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>
"""

_RELS = """<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/3D/3dmodel.model" Id="rel0"
  Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
"""


def _escape(text: str) -> str:
    return (str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;"))


def _model(objects) -> str:
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             '<model unit="millimeter" xml:lang="en-US" '
             'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02" '
             f'xmlns:it="{DENSITY_NAMESPACE}">', " <resources>",
             '  <basematerials id="1">']
    for obj in objects:
        density = f' it:density="{float(obj["density"])!r}"' if obj.get("density") is not None else ""
        lines.append(f'   <base name="{_escape(obj["material"])}" displaycolor="{obj["color"]}"{density}/>')
    lines.append("  </basematerials>")
    for k, obj in enumerate(objects):
        lines.append(f'  <object id="{k + 2}" type="model" name="{_escape(obj["name"])}" pid="1" pindex="{k}">')
        lines.append("   <mesh>")
        lines.append("    <vertices>")
        # 17 significant digits: the file reads back to the same doubles (analyze of it gives spin-it's numbers)
        lines += [f'     <vertex x="{x:.17g}" y="{y:.17g}" z="{z:.17g}"/>' for x, y, z in obj["vertices"]]
        lines.append("    </vertices>")
        lines.append("    <triangles>")
        lines += [f'     <triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in obj["faces"]]
        lines.append("    </triangles>")
        lines.append("   </mesh>")
        lines.append("  </object>")
    lines.append(" </resources>")
    lines.append(" <build>")
    lines += [f'  <item objectid="{k + 2}"/>' for k in range(len(objects))]
    lines.append(" </build>")
    lines.append("</model>")
    return "\n".join(lines) + "\n"


def write_3mf(path, objects, *, label: str | None = None) -> None:
    """Write bodies of different materials as one 3MF package (millimetres), atomically
    (:func:`inertia_tool.output.atomic_target`; check the target first with ``check_targets``).

    Parameters
    ----------
    path : str or path-like
        Output file.
    objects : sequence of dict
        ``{"name", "material", "color" ("#RRGGBBAA"), "vertices" ((n, 3) float, **millimetres**),
        "faces" ((m, 3) int, outward-wound)}`` and optionally ``"density"`` (kg/m³), written on the material
        as ``it:density`` in :data:`~inertia_tool.mesh.threemf.DENSITY_NAMESPACE` (a namespace 3MF consumers
        that do not know it ignore; ``analyze`` reads it back).
    label : str, optional
        The option that named the file, for messages (``"--out"``).
    """
    from ..output import atomic_target

    cleaned = [{**o, "vertices": np.asarray(o["vertices"], dtype=float), "faces": np.asarray(o["faces"], dtype=int)}
               for o in objects]
    with atomic_target(path, label=label) as tmp:
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as archive:
            archive.writestr("[Content_Types].xml", _CONTENT_TYPES)
            archive.writestr("_rels/.rels", _RELS)
            archive.writestr("3D/3dmodel.model", _model(cleaned))
