#!/usr/bin/env python3
"""Compare prespline with OpenCASCADE (the CAD oracle) on STEP and IGES files.

For each file, OpenCASCADE (Python binding `cadquery-ocp`) is run in a fresh process per run, so
no run profits from another's caches:

  read + transfer  STEPControl_Reader / IGESControl_Reader: ReadFile, TransferRoots, OneShape
  mesh             BRepMesh_IncrementalMesh at a linear deflection of 1e-3 of the diagonal of
                   the optimal bounding box (angular deflection 0.5, one thread: the defaults)

Both are timed inside the worker after its OCP imports (Python start-up and module loading,
about a second, are not counted; prespline's times below are whole processes, so the ratios
favour OpenCASCADE slightly). The median of --runs runs is reported. The first run also measures what prespline must
reproduce (DESIGN.md, "CAD files"):

  faces          TopExp_Explorer over faces (every assembly instance counts)
  area           BRepGProp::SurfaceProperties, tolerance 1e-7, in mm^2 (OpenCASCADE converts
                 every file to mm)
  bounds         the optimal bounding box, BRepBndLib::AddOptimal (no triangulation, no shape
                 tolerance; measured before meshing), [[xmin,ymin,zmin],[xmax,ymax,zmax]] in mm
  surface kinds  the dynamic type of each face's BRep_Tool::Surface (Geom_Plane, ...)

and checks them against reference.json (found beside each file, or --reference): same face
count and surface kinds, area and bounds to 1e-9 (relative; bounds relative to the diagonal).
Timings are compared with the reference's only as a ratio, since machines differ.

With --prespline BINARY it also times, wall clock, median of --runs,

  BINARY info FILE --json
  BINARY render FILE --out DIR/x.png --size 1280x720

(environment VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json unless already set,
so rendering uses lavapipe), reads `faces`, `area` and `bounds` from info's JSON and checks them
against OpenCASCADE: same face count, area within 0.2 %, every bound within 0.2 % of the
diagonal. A binary that fails (missing subcommand, non-zero exit, timeout, bad JSON) gives one
line for that file and the comparison goes on.

Usage:
  scripts/occt_compare.py /work/shared/cad                 every .stp/.step/.igs/.iges there
  scripts/occt_compare.py --runs 5 a.stp b.igs
  scripts/occt_compare.py --prespline target/release/prespline --json out.json DIR

Needs `pip install cadquery-ocp` (OCP, OpenCASCADE 8.0; ~70 MB wheel plus VTK). Exit status:
0, or 1 with --strict when a check failed (reference not reproduced, prespline failed or
disagreed), 2 for usage errors and a missing OCP.
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

CAD_SUFFIXES = (".stp", ".step", ".igs", ".iges")
LAVAPIPE_ICD = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json"
# How closely OpenCASCADE must reproduce reference.json (same library, same inputs: only
# rounding may differ) and how closely prespline must agree with OpenCASCADE (DESIGN.md).
REFERENCE_TOL = 1e-9
AGREEMENT_TOL = 2e-3
OCP_MISSING = ("OCP (OpenCASCADE's Python binding) is not importable ({error}); "
               "install it with:  pip install cadquery-ocp")


# -------------------------------------------------------------------------------------------
# The OpenCASCADE worker: one file, one process, JSON to a file (OpenCASCADE prints to stdout).
# -------------------------------------------------------------------------------------------

def occ_worker(path, out_path, measure):
    """Times read + transfer and meshing of `path`; with `measure`, also faces, area, bounds
    and surface kinds. Writes a JSON object to `out_path`."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepGProp import BRepGProp
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.Bnd import Bnd_Box
    from OCP.GProp import GProp_GProps
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.IGESControl import IGESControl_Reader
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    t0 = time.perf_counter()
    step = path.lower().endswith((".stp", ".step"))
    reader = STEPControl_Reader() if step else IGESControl_Reader()
    status = reader.ReadFile(path)
    if status != IFSelect_RetDone:
        raise RuntimeError(f"ReadFile returned {status}")
    reader.TransferRoots()
    shape = reader.OneShape()
    t1 = time.perf_counter()
    if shape.IsNull():
        raise RuntimeError("TransferRoots produced no shape")

    box = Bnd_Box()
    # useTriangulation = False (there is none yet anyway), useShapeTolerance = False.
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    lo, hi = box.CornerMin(), box.CornerMax()
    bounds = [[lo.X(), lo.Y(), lo.Z()], [hi.X(), hi.Y(), hi.Z()]]
    diagonal = math.dist(bounds[0], bounds[1])

    t2 = time.perf_counter()
    mesh = BRepMesh_IncrementalMesh(shape, 1e-3 * diagonal)
    t3 = time.perf_counter()
    result = {"read_transfer_s": t1 - t0, "mesh_s": t3 - t2, "mesh_done": mesh.IsDone()}

    if measure:
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(shape, props, 1e-7)
        faces, kinds = 0, {}
        # TopoDS::Face is a namespace function: `TopoDS.Face` in OCP 8, `TopoDS.Face_s` before.
        to_face = getattr(TopoDS, "Face_s", None) or TopoDS.Face
        explorer = TopExp_Explorer(shape, TopAbs_FACE)
        while explorer.More():
            surface = BRep_Tool.Surface_s(to_face(explorer.Current()))
            kind = surface.DynamicType().Name() if surface is not None else "none"
            kinds[kind] = kinds.get(kind, 0) + 1
            faces += 1
            explorer.Next()
        result.update(faces=faces, area=props.Mass(), bounds=bounds,
                      surface_kinds=dict(sorted(kinds.items())))
    with open(out_path, "w") as f:
        json.dump(result, f)


def run_occ(path, measure, timeout):
    """One fresh worker process; returns its JSON object or raises RuntimeError."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "occ.json")
        cmd = [sys.executable, os.path.abspath(__file__), "--worker", path, out]
        if measure:
            cmd.append("--measure")
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"OpenCASCADE worker timed out after {timeout} s")
        if proc.returncode != 0 or not os.path.exists(out):
            tail = (proc.stderr or proc.stdout).strip().splitlines()[-1:] or ["no output"]
            raise RuntimeError(f"OpenCASCADE worker failed ({proc.returncode}): {tail[0]}")
        with open(out) as f:
            return json.load(f)


# -------------------------------------------------------------------------------------------
# prespline
# -------------------------------------------------------------------------------------------

def run_timed(cmd, env, timeout):
    """(wall seconds, CompletedProcess) or raises RuntimeError with one line."""
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"timed out after {timeout} s")
    except OSError as e:
        raise RuntimeError(str(e))
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        lines = (proc.stderr.strip() or proc.stdout.strip()).splitlines()
        first = lines[0] if lines else "no output"
        raise RuntimeError(f"exit {proc.returncode}: {first[:160]}")
    return wall, proc


def parse_info(text):
    """faces, area, bounds from `info --json`; raises ValueError naming what is wrong."""
    data = json.loads(text)
    faces, area, bounds = data.get("faces"), data.get("area"), data.get("bounds")
    if not isinstance(faces, int):
        raise ValueError(f"faces: {faces!r}")
    if not isinstance(area, (int, float)):
        raise ValueError(f"area: {area!r}")
    ok = (isinstance(bounds, list) and len(bounds) == 2
          and all(isinstance(c, list) and len(c) == 3
                  and all(isinstance(x, (int, float)) for x in c) for c in bounds))
    if not ok:
        raise ValueError(f"bounds: {bounds!r}")
    return faces, float(area), bounds


def run_prespline(binary, path, runs, timeout):
    """Median wall times of info and render, and info's numbers. The two are independent (a
    binary may render a file before it has `info`); `error` joins what failed, one line."""
    env = dict(os.environ)
    env.setdefault("VK_DRIVER_FILES", LAVAPIPE_ICD)
    out = {"info_s": None, "render_s": None, "info": None, "error": None}
    errors = []
    try:
        times = []
        for _ in range(runs):
            wall, proc = run_timed([binary, "info", path, "--json"], env, timeout)
            times.append(wall)
        try:
            out["info"] = parse_info(proc.stdout)
        except (ValueError, json.JSONDecodeError) as e:
            raise RuntimeError(f"unusable --json output ({e})")
        out["info_s"] = statistics.median(times)
    except RuntimeError as e:
        errors.append(f"info: {e}")
    try:
        times = []
        with tempfile.TemporaryDirectory() as tmp:
            png = os.path.join(tmp, "x.png")
            for _ in range(runs):
                cmd = [binary, "render", path, "--out", png, "--size", "1280x720"]
                wall, _ = run_timed(cmd, env, timeout)
                times.append(wall)
            if not os.path.exists(png):
                raise RuntimeError("exit 0 but no image written")
        out["render_s"] = statistics.median(times)
    except RuntimeError as e:
        errors.append(f"render: {e}")
    out["error"] = "; ".join(errors) or None
    return out


# -------------------------------------------------------------------------------------------
# Checks
# -------------------------------------------------------------------------------------------

def compare(faces, area, bounds, ref_faces, ref_area, ref_bounds, tol):
    """(ok, description): face count equal, area and bounds within tol (bounds relative to
    the reference diagonal)."""
    diagonal = math.dist(ref_bounds[0], ref_bounds[1])
    area_rel = abs(area - ref_area) / abs(ref_area) if ref_area else abs(area)
    bound_rel = max(abs(x - y) for c, d in zip(bounds, ref_bounds) for x, y in zip(c, d))
    bound_rel /= diagonal if diagonal else 1.0
    ok = faces == ref_faces and area_rel <= tol and bound_rel <= tol
    what = (f"faces {faces}/{ref_faces} area {area_rel:.1e} bounds {bound_rel:.1e}")
    return ok, what


def find_reference(path, explicit):
    ref_path = explicit or os.path.join(os.path.dirname(path), "reference.json")
    if not os.path.exists(ref_path):
        return None
    with open(ref_path) as f:
        return json.load(f).get(os.path.basename(path))


def occ_version():
    try:
        from importlib.metadata import version
        package = version("cadquery-ocp")
    except Exception:
        package = "unknown"
    import OCP
    return f"cadquery-ocp {package} (OCP {getattr(OCP, '__version__', '?')})"


def expand(paths):
    files = []
    for p in paths:
        if os.path.isdir(p):
            files += sorted(os.path.join(p, f) for f in os.listdir(p)
                            if f.lower().endswith(CAD_SUFFIXES))
        else:
            files.append(p)
    return files


def fmt(x, digits=3):
    return "-" if x is None else f"{x:.{digits}f}"


def main(argv=None):
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        epilog=__doc__.split("\n", 2)[2],
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("files", nargs="+", metavar="FILE_OR_DIR",
                        help="STEP/IGES files, or directories (their .stp/.step/.igs/.iges)")
    parser.add_argument("--runs", type=int, default=3,
                        help="timed runs per file and tool; the median is reported (default 3)")
    parser.add_argument("--prespline", metavar="BINARY",
                        help="also time and check BINARY info --json and BINARY render")
    parser.add_argument("--reference", metavar="JSON",
                        help="reference.json to check against (default: beside each file)")
    parser.add_argument("--json", metavar="OUT", help="write every measurement to OUT as JSON")
    parser.add_argument("--timeout", type=float, default=600.0,
                        help="seconds allowed per process (default 600)")
    parser.add_argument("--strict", action="store_true",
                        help="exit 1 when any check fails")
    parser.add_argument("--worker", nargs=2, metavar=("FILE", "OUT"), help=argparse.SUPPRESS)
    parser.add_argument("--measure", action="store_true", help=argparse.SUPPRESS)
    if argv is None:
        argv = sys.argv[1:]
    if "--worker" in argv:
        i = argv.index("--worker")
        occ_worker(argv[i + 1], argv[i + 2], "--measure" in argv)
        return 0
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error("--runs must be at least 1")
    try:
        import OCP  # noqa: F401  (only to fail early and clearly)
    except ImportError as e:
        print(OCP_MISSING.format(error=e), file=sys.stderr)
        return 2
    files = expand(args.files)
    missing = [f for f in files if not os.path.isfile(f)]
    if missing or not files:
        parser.error(f"no such file: {missing[0]}" if missing else "no STEP/IGES files found")

    print(f"OpenCASCADE: {occ_version()}; {args.runs} run(s) per file, median; "
          f"mesh deflection 1e-3 x diagonal")
    if args.prespline:
        print(f"prespline: {args.prespline} (VK_DRIVER_FILES="
              f"{os.environ.get('VK_DRIVER_FILES', LAVAPIPE_ICD)})")
    results, failed = [], False
    for path in files:
        name = os.path.basename(path)
        row = {"file": name, "path": path}
        try:
            runs = [run_occ(path, i == 0, args.timeout) for i in range(args.runs)]
        except RuntimeError as e:
            print(f"{name}: {e}")
            row["error"] = str(e)
            results.append(row)
            failed = True
            continue
        first = runs[0]
        row["occ"] = {k: first[k] for k in ("faces", "area", "bounds", "surface_kinds")}
        row["occ"]["read_transfer_s"] = statistics.median(r["read_transfer_s"] for r in runs)
        row["occ"]["mesh_s"] = statistics.median(r["mesh_s"] for r in runs)
        row["occ"]["total_s"] = statistics.median(r["read_transfer_s"] + r["mesh_s"]
                                                  for r in runs)
        ref = find_reference(path, args.reference)
        if ref is not None:
            ok, what = compare(first["faces"], first["area"], first["bounds"], ref["faces"],
                               ref["area_mm2"], ref["bounds_mm"], REFERENCE_TOL)
            kinds_ok = first["surface_kinds"] == ref["surface_kinds"]
            row["reference"] = {"ok": ok and kinds_ok, "detail": what, "kinds_ok": kinds_ok,
                                "time_ratio": row["occ"]["total_s"]
                                / (ref["occt_read_transfer_s"] + ref["occt_mesh_s"])}
            failed |= not (ok and kinds_ok)
        if args.prespline:
            p = run_prespline(args.prespline, path, args.runs, args.timeout)
            row["prespline"] = {"info_s": p["info_s"], "render_s": p["render_s"],
                                "error": p["error"]}
            if p["info"] is not None:
                faces, area, bounds = p["info"]
                ok, what = compare(faces, area, bounds, first["faces"], first["area"],
                                   first["bounds"], AGREEMENT_TOL)
                row["prespline"].update(faces=faces, area=area, bounds=bounds,
                                        agrees=ok, agreement=what)
                failed |= not ok
            failed |= p["error"] is not None
        results.append(row)
        print_row(row, bool(args.prespline))

    print_table(results, bool(args.prespline))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"occ": occ_version(), "runs": args.runs, "files": results}, f, indent=1)
    return 1 if (failed and args.strict) else 0


def print_row(row, with_prespline):
    """Progress line per file, so a long run shows where it is."""
    occ = row["occ"]
    line = (f"  {row['file']}: OCC read+transfer {occ['read_transfer_s']:.3f} s, "
            f"mesh {occ['mesh_s']:.3f} s")
    if with_prespline and row["prespline"]["error"]:
        line += f"; prespline {row['prespline']['error']}"
    print(line, flush=True)


def print_table(results, with_prespline):
    header = ["file", "faces", "area mm2", "OCC read+tr s", "OCC mesh s", "OCC total s",
              "reference (faces/area/bounds/kinds)"]
    if with_prespline:
        header += ["info s", "render s", "OCC/info", "OCC/render", "prespline vs OCC"]
    rows = []
    for r in results:
        if "occ" not in r:
            rows.append([r["file"], "-", "-", "-", "-", "-", "OCC failed: " + r["error"]])
            continue
        occ = r["occ"]
        ref = r.get("reference")
        ref_text = "no reference" if ref is None else (
            ("ok " if ref["ok"] else "MISMATCH ") + ref["detail"]
            + ("" if ref["kinds_ok"] else " kinds differ"))
        cells = [r["file"], str(occ["faces"]), f"{occ['area']:.6g}",
                 fmt(occ["read_transfer_s"]), fmt(occ["mesh_s"]), fmt(occ["total_s"]), ref_text]
        if with_prespline:
            p = r["prespline"]

            def ratio(t):
                return f"{occ['total_s'] / t:.2f}" if t else "-"

            if p["error"] and p.get("agrees") is None:
                agreement = "failed: " + p["error"]
            else:
                agreement = (("ok " if p.get("agrees") else "DISAGREES ") + p.get("agreement", "")
                             + (f"; {p['error']}" if p["error"] else ""))
            cells += [fmt(p["info_s"]), fmt(p["render_s"]), ratio(p["info_s"]),
                      ratio(p["render_s"]), agreement]
        rows.append(cells)
    widths = [max(len(h), *(len(c[i]) for c in rows)) for i, h in enumerate(header)]
    print()
    print(" | ".join(h.ljust(w) for h, w in zip(header, widths)))
    print("-|-".join("-" * w for w in widths))
    for c in rows:
        print(" | ".join(x.ljust(w) for x, w in zip(c, widths)))


if __name__ == "__main__":
    sys.exit(main())
