#!/usr/bin/env python3
"""Check every OpenDRIVE (.xodr) and OpenSCENARIO XML (.xosc) file of a directory with real tools.

    tools/openscenario_check.py DIR [--json] [--python PY] [--keep-work WORKDIR]

For each *.xodr / *.xosc directly in DIR (not recursive, sorted by name):

  .xodr  ASAM checker bundle "xodrBundle" (pip asam-qc-opendrive 1.0.0), run as
         `PY -m qc_opendrive -c CONFIG.xml`, whose result file (.xqar) is read back;
         then SUMO's netconvert imports it and the resulting .net.xml is summarised.
  .xosc  ASAM checker bundle "xoscBundle" (pip asam-qc-openscenarioxml 1.0.0), run as
         `PY -m qc_openscenario -c CONFIG.xml`; then the file is read back with
         scenariogeneration's xosc.ParseOpenScenario (scenarios, catalogs and
         parameter value distributions alike).

The checker configuration both bundles take (qc-framework format) is

    <Config>
      <Param name="InputFile" value="/abs/path/file.xosc"/>
      <CheckerBundle application="xoscBundle">          (or xodrBundle)
        <Param name="resultFile" value="/abs/path/result.xqar"/>
      </CheckerBundle>
    </Config>

and the .xqar holds CheckerResults/CheckerBundle/Checker[@status]/Issue/Locations.

This script uses only the standard library; the tools run in the interpreter PY, found as:
--python, else $OPENSCENARIO_PYTHON, else this interpreter if it can import them, else
.venv-xosc/bin/python in the current directory or in the repository root.
tools/openscenario_setup.sh creates that venv and prints its python.

Output: a readable per-file summary, or with --json one JSON document
  {"files": [{"file", "kind", "issues": [...], "checks": {"executed", "skipped", ...},
              "netconvert": {...} | null, "readback": {"ok", "error", ...} | null}],
   "total_issues": n, ...}

Exit status: 0 when no file has an issue (of any level), netconvert reported no error and
every read-back succeeded; 1 otherwise; 2 on usage errors (bad DIR, no .xodr/.xosc in it,
tools not found).

Besides the bundles' own issues, this script adds issues of its own (their checker_id
starts with "openscenario_check."):
  - bundle_failed / checker_error: the bundle crashed or wrote no result, or a checker
    ended with status "error";
  - schema_not_checked: the schema checker was skipped (the header's revMajor.revMinor has
    no schema in the bundle), which silently skips every later check;
  - unresolved_path: a .xosc RoadNetwork/LogicFile, ScenarioFile or catalog Directory path
    that does not exist (the bundle does not check it).
"""

import argparse
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

BUNDLES = {
    # kind: (python module, bundle name, schema checker id)
    "xodr": ("qc_opendrive", "xodrBundle", "check_asam_xodr_xml_valid_schema"),
    "xosc": ("qc_openscenario", "xoscBundle", "check_asam_xosc_xml_valid_schema"),
}
LEVELS = {"1": "error", "2": "warning", "3": "information"}
TOOL_MODULES = ("qc_openscenario", "qc_opendrive", "qc_baselib", "scenariogeneration")
BUNDLE_TIMEOUT = 600
NETCONVERT_TIMEOUT = 300

# netconvert (SUMO 1.15 in Debian 12) options:
#   --xml-validation never        Debian's `sumo` package without `sumo-tools` has no
#                                 $SUMO_HOME/data: validating the built-in type map then
#                                 fails with "invalid document structure"
#   --type-files TYPEMAP          the lane types to import (NETCONVERT_TYPEMAP below):
#                                 SUMO's opendriveNetconvert.typ.xml plus its pedestrian and
#                                 bicycle add-ons, so sidewalks import as pedestrian lanes and
#                                 biking lanes as bicycle lanes (SUMO's built-in map drops both)
#   --opendrive.internal-shapes   shape junction-internal lanes from the connecting roads
#   --no-turnarounds              only the connections the file defines (no U-turns added)
#   --offset.disable-normalization  keep the file's x/y coordinates
#   --output.original-names       keep "<road id>_<lane id>" of the .xodr as lane param origId
# Internal (junction) lanes are built by default (no --no-internal-links).
# Not used: --opendrive.import-all-lanes, which would also import shoulder, border, median,
# curb and none lanes (as lanes that allow nothing).
NETCONVERT_OPTIONS = [
    "--xml-validation", "never",
    "--opendrive.internal-shapes",
    "--no-turnarounds",
    "--offset.disable-normalization",
    "--output.original-names",
]
# from SUMO 1.15 data/typemap/opendriveNetconvert{,Pedestrians,Bicycle}.typ.xml, plus the
# OpenDRIVE 1.7/1.8 lane types that map lacks (connectingRamp, slipLane, bus, taxi, HOV,
# shared, walking, curb) as their closest SUMO equivalents
_CARS = 'disallow="pedestrian rail rail_urban rail_electric rail_fast tram ship"'
_RAMP = 'disallow="pedestrian bicycle moped rail rail_urban rail_electric rail_fast tram ship"'
NETCONVERT_TYPEMAP = f"""<types>
    <type id="driving"        priority="1"  speed="13.89" width="3.65" {_CARS}/>
    <type id="stop"           priority="1"  speed="13.89" width="3.65" {_CARS}/>
    <type id="restricted"     priority="0"  speed="13.89" width="3.65" disallow="all"/>
    <type id="parking"        priority="1"  speed="1.39"  width="2.50" {_CARS}/>
    <type id="entry"          priority="1"  speed="22.22" width="3.65" {_CARS}/>
    <type id="exit"           priority="1"  speed="22.22" width="3.65" {_CARS}/>
    <type id="offRamp"        priority="1"  speed="22.22" width="3.65" {_RAMP}/>
    <type id="onRamp"         priority="1"  speed="22.22" width="3.65" {_RAMP}/>
    <type id="connectingRamp" priority="1"  speed="22.22" width="3.65" {_RAMP}/>
    <type id="slipLane"       priority="1"  speed="13.89" width="3.65" {_CARS}/>
    <type id="roadWorks"      priority="0"  speed="1.39"  width="3.65" allow="authority"/>
    <type id="tram"           priority="2"  speed="13.89" width="3.65" allow="tram"/>
    <type id="rail"           priority="3"  speed="33.33" width="3.65" allow="rail rail_urban rail_electric rail_fast"/>
    <type id="biking"         priority="-1" speed="5.56"  width="1.50" allow="bicycle"/>
    <type id="sidewalk"       priority="-2" speed="2.78"  width="2.50" allow="pedestrian"/>
    <type id="walking"        priority="-2" speed="2.78"  width="2.50" allow="pedestrian"/>
    <type id="shared"         priority="-1" speed="5.56"  width="2.50" allow="pedestrian bicycle"/>
    <type id="bus"            priority="1"  speed="13.89" width="3.65" allow="bus"/>
    <type id="taxi"           priority="1"  speed="13.89" width="3.65" allow="taxi"/>
    <type id="HOV"            priority="1"  speed="13.89" width="3.65" allow="hov bus taxi"/>
    <type id="none"           priority="0"  speed="1.39"  width="1.0"  disallow="all" discard="true"/>
    <type id="shoulder"       priority="0"  speed="1.39"  width="1.0"  disallow="all" discard="true"/>
    <type id="border"         priority="0"  speed="1.39"  width="0.1"  disallow="all" discard="true"/>
    <type id="median"         priority="0"  speed="1.39"  width="0.1"  disallow="all" discard="true"/>
    <type id="curb"           priority="0"  speed="1.39"  width="0.1"  disallow="all" discard="true"/>
    <type id="special1"       priority="1"  speed="22.22" width="3.65" allow="custom1" discard="true"/>
    <type id="special2"       priority="1"  speed="22.22" width="3.65" allow="custom2" discard="true"/>
    <type id="special3"       priority="1"  speed="22.22" width="3.65" allow="custom1 custom2" discard="true"/>
    <type id="mwyEntry"       priority="1"  speed="22.22" width="3.65" {_RAMP}/>
    <type id="mwyExit"        priority="1"  speed="22.22" width="3.65" {_RAMP}/>
    <type id="bidirectional"  priority="1"  speed="1.39"  width="3.65" {_CARS}/>
</types>
"""
NETCONVERT_ENV_WARNINGS = (
    "Environment variable SUMO_HOME is not set",
)

READBACK_CODE = r"""
import contextlib, json, sys, traceback, warnings
path = sys.argv[1]
out = {"ok": False, "error": None, "type": None, "warnings": []}
try:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with contextlib.redirect_stdout(sys.stderr):
            from scenariogeneration import xosc
            obj = xosc.ParseOpenScenario(path)
    out["ok"] = True
    out["type"] = type(obj).__name__
    out["warnings"] = sorted({str(w.message) for w in caught})
except BaseException as e:  # report anything, including SystemExit from the library
    out["error"] = f"{type(e).__name__}: {e}"
    out["traceback"] = traceback.format_exc(limit=6)
print(json.dumps(out))
"""


class UsageError(Exception):
    pass


# --------------------------------------------------------------------------- tools


def _can_import_here():
    return all(importlib.util.find_spec(m) is not None for m in TOOL_MODULES)


def _can_import_with(python):
    try:
        r = subprocess.run(
            [python, "-c", "import " + ", ".join(TOOL_MODULES)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=120,
        )
        return r.returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def find_tool_python(explicit):
    if explicit:
        if not _can_import_with(explicit):
            raise UsageError(f"--python {explicit}: cannot import {', '.join(TOOL_MODULES)}")
        return explicit
    env = os.environ.get("OPENSCENARIO_PYTHON")
    if env:
        if not _can_import_with(env):
            raise UsageError(f"OPENSCENARIO_PYTHON={env}: cannot import {', '.join(TOOL_MODULES)}")
        return env
    if _can_import_here():
        return sys.executable
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    for base in (os.getcwd(), repo):
        cand = os.path.join(base, ".venv-xosc", "bin", "python")
        if os.path.exists(cand) and _can_import_with(cand):
            return cand
    raise UsageError(
        "the checker packages are not installed: run "
        "`PY=$(bash tools/openscenario_setup.sh .venv-xosc)` and pass --python \"$PY\" "
        "(or set OPENSCENARIO_PYTHON)"
    )


# --------------------------------------------------------------------------- ASAM bundles


def write_config(path, input_file, bundle, result_file):
    root = ET.Element("Config")
    ET.SubElement(root, "Param", name="InputFile", value=input_file)
    cb = ET.SubElement(root, "CheckerBundle", application=bundle)
    ET.SubElement(cb, "Param", name="resultFile", value=result_file)
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)


def _tool_issue(checker_id, description, locations=None):
    return {
        "checker_id": checker_id,
        "rule_uid": None,
        "level": "error",
        "description": description,
        "locations": locations or [],
        "location": None,
    }


def _location_text(loc):
    parts = []
    if "row" in loc or "column" in loc:
        parts.append(f"line {loc.get('row')}:{loc.get('column')}")
    if "xpath" in loc:
        parts.append(loc["xpath"])
    if "inertial" in loc:
        x, y, z = (loc["inertial"][k] for k in ("x", "y", "z"))
        parts.append(f"(x={x:.2f}, y={y:.2f}, z={z:.2f})")
    text = " ".join(parts)
    if loc.get("description"):
        text = f"{text}: {loc['description']}" if text else loc["description"]
    return text


def parse_xqar(path):
    """Return (issues, checkers) from a qc-framework result file."""
    root = ET.parse(path).getroot()
    issues, checkers = [], []
    for bundle in root.iter("CheckerBundle"):
        for checker in bundle.findall("Checker"):
            cid = checker.get("checkerId")
            rules = [r.get("ruleUID") for r in checker.findall("AddressedRule")]
            checkers.append({
                "id": cid,
                "status": checker.get("status"),
                # Result.write_to_file(generate_summary=True) appends "N issue(s) are found."
                "summary": re.sub(r"\s*\d+ issue\(s\) are found\.\s*$", "",
                                  checker.get("summary", "")),
                "rules": rules,
            })
            for issue in checker.findall("Issue"):
                locs = []
                for le in issue.findall("Locations"):
                    loc = {"description": le.get("description", "")}
                    for fl in le.findall("FileLocation"):
                        for k in ("row", "column", "offset"):
                            if fl.get(k) is not None:
                                loc[k] = int(fl.get(k))
                    for xl in le.findall("XMLLocation"):
                        loc["xpath"] = xl.get("xpath")
                    for il in le.findall("InertialLocation"):
                        loc["inertial"] = {k: float(il.get(k)) for k in ("x", "y", "z")}
                    locs.append(loc)
                issues.append({
                    "checker_id": cid,
                    "rule_uid": issue.get("ruleUID"),
                    "level": LEVELS.get(issue.get("level"), issue.get("level")),
                    "description": issue.get("description", ""),
                    "locations": locs,
                    "location": _location_text(locs[0]) if locs else None,
                })
    return issues, checkers


def run_bundle(python, kind, path, workdir):
    module, bundle, schema_checker = BUNDLES[kind]
    stem = os.path.basename(path)
    cfg = os.path.join(workdir, f"{stem}.{bundle}.config.xml")
    xqar = os.path.join(workdir, f"{stem}.{bundle}.xqar")
    log = os.path.join(workdir, f"{stem}.{bundle}.log")
    write_config(cfg, path, bundle, xqar)
    if os.path.exists(xqar):  # a stale result from an earlier --keep-work run
        os.remove(xqar)
    issues, checkers = [], []
    try:
        r = subprocess.run(
            [python, "-m", module, "-c", cfg], cwd=workdir,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            timeout=BUNDLE_TIMEOUT,
        )
        with open(log, "w") as f:
            f.write(r.stdout)
        if r.returncode != 0 or not os.path.exists(xqar):
            tail = "\n".join(r.stdout.strip().splitlines()[-5:])
            issues.append(_tool_issue(
                "openscenario_check.bundle_failed",
                f"{module} exited with {r.returncode} and "
                f"{'wrote' if os.path.exists(xqar) else 'did not write'} {os.path.basename(xqar)}: {tail}",
            ))
    except subprocess.TimeoutExpired:
        issues.append(_tool_issue("openscenario_check.bundle_failed",
                                  f"{module} timed out after {BUNDLE_TIMEOUT} s"))
    if os.path.exists(xqar):
        try:
            bi, checkers = parse_xqar(xqar)
            issues.extend(bi)
        except ET.ParseError as e:
            issues.append(_tool_issue("openscenario_check.bundle_failed",
                                      f"cannot read {os.path.basename(xqar)}: {e}"))
    by_status = {}
    for c in checkers:
        by_status.setdefault(c["status"] or "none", []).append(c)
    for c in by_status.get("error", []):
        issues.append(_tool_issue(
            "openscenario_check.checker_error",
            f"checker {c['id']} ended with an internal error: {c['summary']}",
        ))
    schema = next((c for c in checkers if c["id"] == schema_checker), None)
    if schema is not None and schema["status"] == "skipped" and not any(
        i["level"] == "error" for i in issues
    ):
        issues.append(_tool_issue(
            "openscenario_check.schema_not_checked",
            f"{schema_checker} was skipped ({schema['summary']}), so every later check was "
            "skipped too: the header's revMajor/revMinor has no schema in the bundle",
        ))
    checks = {
        "executed": len(by_status.get("completed", [])),
        "skipped": len(by_status.get("skipped", [])),
        "errored": len(by_status.get("error", [])),
        "total": len(checkers),
        "skipped_checks": [
            {"id": c["id"], "reason": c["summary"]} for c in by_status.get("skipped", [])
        ],
        "executed_checks": [c["id"] for c in by_status.get("completed", [])],
    }
    return issues, checks


# --------------------------------------------------------------------------- netconvert


def _permission_class(lane):
    allow = lane.get("allow")
    disallow = lane.get("disallow")
    if allow is not None:
        return "allow=" + allow
    if disallow is not None:
        return "disallow=" + disallow
    return "all"


def summarize_net(net_path):
    root = ET.parse(net_path).getroot()
    edges = []
    internal_edges = 0
    for e in root.findall("edge"):
        if e.get("function") == "internal":
            internal_edges += 1
            continue
        lanes = []
        for ln in e.findall("lane"):
            lparams = {p.get("key"): p.get("value") for p in ln.findall("param")}
            lanes.append({
                "id": ln.get("id"),
                "origId": lparams.get("origId"),  # "<road id>_<lane id>" in the .xodr
                "index": int(ln.get("index", "0")),
                "type": ln.get("type"),
                "permissions": _permission_class(ln),
                "width": float(ln.get("width")) if ln.get("width") else None,
                "speed": float(ln.get("speed")) if ln.get("speed") else None,
                "length": float(ln.get("length")) if ln.get("length") else None,
            })
        roads = sorted({ln["origId"].rsplit("_", 1)[0] for ln in lanes if ln["origId"]})
        edges.append({
            "id": e.get("id"),
            "from": e.get("from"),
            "to": e.get("to"),
            "type": e.get("type"),
            "function": e.get("function", "normal"),
            "roads": roads,  # the OpenDRIVE road(s) the edge comes from
            "lanes": lanes,
        })
    junctions = [j for j in root.findall("junction") if j.get("type") != "internal"]
    jtypes = {}
    for j in junctions:
        jtypes[j.get("type")] = jtypes.get(j.get("type"), 0) + 1
    connections = [
        c for c in root.findall("connection")
        if not c.get("from", "").startswith(":") and not c.get("to", "").startswith(":")
    ]
    lanes_by_permissions, lanes_by_type = {}, {}
    for e in edges:
        for ln in e["lanes"]:
            lanes_by_permissions[ln["permissions"]] = lanes_by_permissions.get(ln["permissions"], 0) + 1
            lanes_by_type[ln["type"]] = lanes_by_type.get(ln["type"], 0) + 1
    return {
        "edges": len(edges),
        "internal_edges": internal_edges,
        "lanes": sum(len(e["lanes"]) for e in edges),
        "lanes_by_type": lanes_by_type,
        "lanes_by_permissions": lanes_by_permissions,
        "junctions": len(junctions),
        "junction_types": jtypes,
        "connections": len(connections),
        "edge_list": edges,
    }


def run_netconvert(path, workdir):
    exe = shutil.which("netconvert")
    if exe is None:
        return {"ok": False, "command": None, "returncode": None, "errors": [
            "netconvert not found on PATH (tools/openscenario_setup.sh installs Debian's sumo)"
        ], "warnings": [], "net": None}
    stem = os.path.basename(path)
    out = os.path.join(workdir, stem + ".net.xml")
    errlog = os.path.join(workdir, stem + ".netconvert.log")
    for stale in (out, errlog):
        if os.path.exists(stale):
            os.remove(stale)
    typemap = os.path.join(workdir, "opendrive-lane-types.typ.xml")
    if not os.path.exists(typemap):
        with open(typemap, "w") as fh:
            fh.write(NETCONVERT_TYPEMAP)
    cmd = [exe, "--opendrive-files", path, "-o", out, "--type-files", typemap,
           *NETCONVERT_OPTIONS, "--error-log", errlog]
    env = dict(os.environ)
    if not os.path.isdir(os.path.join(env.get("SUMO_HOME", ""), "data")) and os.path.isdir(
        "/usr/share/sumo/data"
    ):
        env["SUMO_HOME"] = "/usr/share/sumo"
    try:
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           timeout=NETCONVERT_TIMEOUT, env=env)
        rc, text = r.returncode, (r.stderr or "") + (r.stdout or "")
    except subprocess.TimeoutExpired:
        rc, text = None, f"Error: netconvert timed out after {NETCONVERT_TIMEOUT} s"
    warnings, errors, env_notes = [], [], []
    current = None
    for line in text.splitlines():
        if line.startswith("Warning: "):
            msg = line[len("Warning: "):]
            if msg.startswith(NETCONVERT_ENV_WARNINGS):
                env_notes.append(msg)
                current = None
            else:
                warnings.append(msg)
                current = warnings
        elif line.startswith("Error: "):
            errors.append(line[len("Error: "):])
            current = errors
        elif line.startswith(" ") and current is not None and current:
            current[-1] += " " + line.strip()
        elif re.search(r"Assertion .* failed|Segmentation fault|terminate called", line):
            errors.append(line.strip())
            current = None
        else:
            current = None
    if rc is not None and rc < 0:
        errors.append(f"netconvert was killed by signal {-rc}")
    elif rc not in (0, None) and not errors:
        errors.append(f"netconvert exited with {rc}")
    net = None
    if rc == 0 and os.path.exists(out):
        try:
            net = summarize_net(out)
        except ET.ParseError as e:
            errors.append(f"cannot parse {os.path.basename(out)}: {e}")
    elif rc == 0:
        errors.append("netconvert wrote no network")
    return {
        "ok": rc == 0 and not errors,
        "command": " ".join(cmd),
        "returncode": rc,
        "errors": errors,
        "warnings": warnings,
        "environment_notes": env_notes,
        "net": net,
    }


# --------------------------------------------------------------------------- referenced files


def check_xosc_paths(path):
    """Issues for RoadNetwork/LogicFile, ParameterValueDistribution/ScenarioFile and
    CatalogLocations/*/Directory paths that do not exist (relative paths are taken from the
    .xosc file's directory). The ASAM bundle does not check this: a missing LogicFile only
    makes it skip the signal-id check."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        return []  # the bundle reports invalid XML

    def local(tag):
        return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""

    params = {}
    for child in root:
        if local(child.tag) == "ParameterDeclarations":
            for pd in child:
                if pd.get("name") is not None:
                    params[pd.get("name")] = pd.get("value")
    base = os.path.dirname(os.path.abspath(path))
    issues = []
    for el in root.iter():
        name = local(el.tag)
        attr = {"LogicFile": "filepath", "ScenarioFile": "filepath", "Directory": "path"}.get(name)
        if attr is None or el.get(attr) is None:
            continue
        value = el.get(attr)
        if value.startswith("$") and not value.startswith("${"):
            value = params.get(value[1:])
            if value is None:
                continue
        elif value.startswith("${"):
            continue
        target = value if os.path.isabs(value) else os.path.join(base, value)
        exists = os.path.isdir(target) if name == "Directory" else os.path.isfile(target)
        if not exists:
            issues.append(_tool_issue(
                "openscenario_check.unresolved_path",
                f"{name}/@{attr} '{el.get(attr)}' does not exist (resolved to {target})",
                [{"description": f"{name} {attr}={el.get(attr)!r}"}],
            ))
            issues[-1]["location"] = f"{name}/@{attr}"
    return issues


# --------------------------------------------------------------------------- read-back


def run_readback(python, path):
    try:
        r = subprocess.run([python, "-c", READBACK_CODE, path], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, timeout=BUNDLE_TIMEOUT)
    except subprocess.TimeoutExpired:
        return {"ok": False, "error": f"read-back timed out after {BUNDLE_TIMEOUT} s",
                "type": None, "warnings": []}
    lines = r.stdout.strip().splitlines()
    if r.returncode == 0 and lines:
        try:
            return json.loads(lines[-1])
        except json.JSONDecodeError:
            pass
    tail = "\n".join((r.stderr or "").strip().splitlines()[-5:])
    return {"ok": False, "error": f"read-back process failed ({r.returncode}): {tail}",
            "type": None, "warnings": []}


# --------------------------------------------------------------------------- main


def check_dir(directory, python, workdir):
    names = sorted(
        n for n in os.listdir(directory)
        if n.endswith((".xodr", ".xosc")) and os.path.isfile(os.path.join(directory, n))
    )
    if not names:
        raise UsageError(f"no .xodr or .xosc file in {directory}")
    files = []
    for name in names:
        path = os.path.abspath(os.path.join(directory, name))
        kind = "xodr" if name.endswith(".xodr") else "xosc"
        issues, checks = run_bundle(python, kind, path, workdir)
        if kind == "xosc":
            issues.extend(check_xosc_paths(path))
        entry = {
            "file": os.path.join(directory, name),
            "kind": kind,
            "issues": issues,
            "checks": checks,
            "netconvert": run_netconvert(path, workdir) if kind == "xodr" else None,
            "readback": run_readback(python, path) if kind == "xosc" else None,
        }
        files.append(entry)
    total = sum(len(f["issues"]) for f in files)
    nc_failures = sum(1 for f in files if f["netconvert"] and not f["netconvert"]["ok"])
    rb_failures = sum(1 for f in files if f["readback"] and not f["readback"]["ok"])
    by_level = {}
    for f in files:
        for i in f["issues"]:
            by_level[i["level"]] = by_level.get(i["level"], 0) + 1
    return {
        "files": files,
        "total_issues": total,
        "issues_by_level": by_level,
        "netconvert_failures": nc_failures,
        "readback_failures": rb_failures,
        "ok": total == 0 and nc_failures == 0 and rb_failures == 0,
    }


def print_human(report, out=sys.stdout):
    w = out.write
    for f in report["files"]:
        w(f"== {f['file']} ({f['kind']})\n")
        c = f["checks"]
        w(f"  checks: {c['executed']} executed, {c['skipped']} skipped"
          + (f", {c['errored']} errored" if c["errored"] else "") + "\n")
        for s in c["skipped_checks"]:
            w(f"    skipped {s['id']}: {s['reason']}\n")
        if f["issues"]:
            w(f"  issues: {len(f['issues'])}\n")
            for i in f["issues"]:
                rule = f" [{i['rule_uid']}]" if i["rule_uid"] else ""
                w(f"    {i['level'].upper()} {i['checker_id']}{rule}: {i['description'].strip()}\n")
                for loc in i["locations"][:3]:
                    w(f"        at {_location_text(loc)}\n")
                if len(i["locations"]) > 3:
                    w(f"        ... {len(i['locations']) - 3} more location(s)\n")
        else:
            w("  issues: none\n")
        nc = f["netconvert"]
        if nc is not None:
            if nc["net"]:
                n = nc["net"]
                perms = ", ".join(f"{v} {k}" for k, v in sorted(n["lanes_by_type"].items(), key=str))
                w(f"  netconvert: {'ok' if nc['ok'] else 'FAILED'}: {n['edges']} edges, "
                  f"{n['lanes']} lanes ({perms}), {n['junctions']} junctions "
                  f"{n['junction_types']}, {n['connections']} connections, "
                  f"{n['internal_edges']} internal edges\n")
                for e in n["edge_list"][:20]:
                    lanes = ", ".join(f"{ln['type']} {ln['width']}m {ln['permissions']}" for ln in e["lanes"])
                    w(f"    edge {e['id']} (road {','.join(e['roads'])}; {e['from']} -> {e['to']}): "
                      f"{len(e['lanes'])} lanes [{lanes}]\n")
                if len(n["edge_list"]) > 20:
                    w(f"    ... {len(n['edge_list']) - 20} more edge(s) (see --json)\n")
            else:
                w(f"  netconvert: FAILED (exit {nc['returncode']})\n")
            for msg in nc["errors"]:
                w(f"    error: {msg}\n")
            for msg in nc["warnings"][:10]:
                w(f"    warning: {msg}\n")
            if len(nc["warnings"]) > 10:
                w(f"    ... {len(nc['warnings']) - 10} more warning(s)\n")
        rb = f["readback"]
        if rb is not None:
            if rb["ok"]:
                w(f"  read-back: ok ({rb['type']})\n")
            else:
                w(f"  read-back: FAILED: {rb['error']}\n")
            for msg in rb.get("warnings", []):
                w(f"    warning: {msg}\n")
    lv = ", ".join(f"{v} {k}" for k, v in sorted(report["issues_by_level"].items())) or "none"
    w(f"TOTAL: {report['total_issues']} issue(s) ({lv}) in {len(report['files'])} file(s); "
      f"netconvert failures: {report['netconvert_failures']}; "
      f"read-back failures: {report['readback_failures']} -> {'OK' if report['ok'] else 'FAIL'}\n")


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="Check the .xodr/.xosc files of DIR with the ASAM quality checkers, "
                    "netconvert and a scenariogeneration read-back.")
    ap.add_argument("dir", metavar="DIR")
    ap.add_argument("--json", action="store_true", help="print one JSON document")
    ap.add_argument("--python", help="interpreter with the checker packages "
                    "(default: $OPENSCENARIO_PYTHON, this one, or .venv-xosc/bin/python)")
    ap.add_argument("--keep-work", metavar="WORKDIR",
                    help="write configs, .xqar results, logs and .net.xml files there and keep them")
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:
        return 2 if e.code else 0
    try:
        if not os.path.isdir(args.dir):
            raise UsageError(f"{args.dir} is not a directory")
        python = find_tool_python(args.python)
        if args.keep_work:
            os.makedirs(args.keep_work, exist_ok=True)
            report = check_dir(args.dir, python, os.path.abspath(args.keep_work))
        else:
            with tempfile.TemporaryDirectory(prefix="openscenario_check.") as wd:
                report = check_dir(args.dir, python, wd)
    except UsageError as e:
        print(f"openscenario_check.py: {e}", file=sys.stderr)
        return 2
    report["tool_python"] = python
    if args.json:
        json.dump(report, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print_human(report)
    return 0 if report["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
