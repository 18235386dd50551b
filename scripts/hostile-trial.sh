#!/usr/bin/env bash
# A trial of hostile and careless inputs against the surfaces that read what users hand
# them: mesh files (STL, OBJ, PLY, glTF), text, lists, fields, profiles, `sdfc fmt`,
# `sdfc lsp` and special files. Each input runs once, alone, under a timeout, its peak
# memory measured (/usr/bin/time); it is held when the command ends by itself within the
# time, exits 0, 1 or 2 (a non-zero exit with a message on stderr), prints no panic and stays
# within the memory; otherwise it failed, and the line says why (panic, hang, silent exit,
# signal, memory). The language server's cases end with `shutdown` and `exit`: held only
# when it answers the shutdown and exits 0, so every case also checks that it kept serving.
#
# Usage: scripts/hostile-trial.sh [SDFC] [SECONDS] [MIB]
#   SDFC     the binary (default target/release/sdfc)
#   SECONDS  the timeout of one input (default 10)
#   MIB      the memory one input may take (default 512)
# Prints one line per input (`held` or `FAILED`, the surface, the case, exit, seconds, MiB)
# and the counts; exits 1 when any failed. The inputs are written to a temporary folder,
# removed at the end (kept with KEEP=1).
set -euo pipefail
cd "$(dirname "$0")/.."
sdfc=$(realpath "${1:-target/release/sdfc}")
seconds=${2:-10}
mib=${3:-512}
work=$(mktemp -d /tmp/sdfc-hostile.XXXXXX)
[ "${KEEP:-0}" = 1 ] || trap 'rm -rf "$work"' EXIT
exec python3 - "$sdfc" "$seconds" "$mib" "$work" <<'PY'
import json, os, signal, struct, subprocess, sys, time

sdfc, seconds, mib, work = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
os.chdir(work)
cases = []  # (surface, name, argv, stdin bytes or None, lsp)

def put(name, data):
    with open(name, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())

def scene(surface, name, body, *extra):
    put(name + ".sdf", "light point { position: (0, 5, -5) }\n" + body + "\n")
    cases.append((surface, name, ["check", name + ".sdf", *extra], None, False))

def render(surface, name, body):
    put(name + ".sdf", "light point { position: (0, 5, -5) }\nrender { width: 32, height: 24 }\n" + body + "\n")
    cases.append((surface, name, ["render", name + ".sdf", "-o", name + ".png", "--backend", "cpu"], None, False))

def mesh_file(name, data):
    put(name, data)
    scene("mesh file", name, 'scene { mesh("%s"); }' % name)

# ---- mesh files -------------------------------------------------------------------------
tri = struct.pack("<12f", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0) + b"\0\0"
mesh_file("zero_triangles.stl", b"\0" * 80 + struct.pack("<I", 0))
mesh_file("nan_corner.stl", b"\0" * 80 + struct.pack("<I", 1) + struct.pack("<12f", 0, 0, 1, float("nan"), 0, 0, 1, 0, 0, 0, 1, 0) + b"\0\0")
mesh_file("inf_corner.stl", b"\0" * 80 + struct.pack("<I", 1) + struct.pack("<12f", 0, 0, 1, float("inf"), 0, 0, 1, 0, 0, 0, 1, 0) + b"\0\0")
mesh_file("trailing_bytes.stl", b"solid" + b"\0" * 75 + struct.pack("<I", 1) + tri + b"\xff" * 1000)
mesh_file("count_4g.stl", b"\0" * 80 + struct.pack("<I", 0xFFFFFFFF) + tri)
mesh_file("overflow_vertex.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 1e400 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\nendsolid a\n")
mesh_file("only_solid.stl", "solid a\nendsolid a\n")
mesh_file("four_vertices.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 0\nendloop\nendfacet\nendsolid a\n")
mesh_file("empty.stl", b"")
mesh_file("empty.obj", b"")
mesh_file("empty.ply", b"")
mesh_file("empty.glb", b"")
mesh_file("negative_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -5 -6 -7\n")
mesh_file("zero_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")
mesh_file("huge_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3 99999999999999999999 2\n")
mesh_file("nan_vertex.obj", "v nan nan nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
mesh_file("two_corners.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n")
mesh_file("no_faces.obj", "v 0.5 0.25 0.125\n" * 400000)
mesh_file("slashes.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1// 2//// /3\n")
mesh_file("negative_count.ply", "ply\nformat ascii 1.0\nelement vertex -1\nproperty float x\nproperty float y\nproperty float z\nend_header\n")
mesh_file("no_end_header.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n")
mesh_file("list_count_255.ply", b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" + struct.pack(">9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + b"\xff" + b"\0\0\0\0" * 3)
mesh_file("list_count_4g.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint uint vertex_indices\nend_header\n" + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<I", 0xFFFFFFF0))
mesh_file("doubles_and_extras.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\nproperty float quality\nend_header\n0 0 0 1\n1 0 0 2\n0 1 0 3\n3 0 1 2 0.5\n")
mesh_file("unknown_format.ply", "ply\nformat binary_middle_endian 1.0\nelement vertex 0\nend_header\n")

def glb(doc, bin_=b"", length=None, version=2):
    j = doc if isinstance(doc, bytes) else json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    body = struct.pack("<II", len(j), 0x4E4F534A) + j
    if bin_ is not None and len(bin_):
        bin_ += b"\0" * (-len(bin_) % 4)
        body += struct.pack("<II", len(bin_), 0x004E4942) + bin_
    total = 12 + len(body)
    return struct.pack("<III", 0x46546C67, version, total if length is None else length) + body

pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
def doc(**over):
    d = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": 36}],
         "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
         "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
         "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}]}
    for k, v in over.items():
        d[k] = v
    return d
mesh_file("length_past_end.glb", glb(doc(), pos, length=1 << 31))
mesh_file("nested_json.glb", glb(b"[" * 100000 + b"]" * 100000, pos))
mesh_file("json_not_utf8.glb", glb(b'{"asset":"\xff\xfe"}', pos))
mesh_file("count_2_53.glb", glb(doc(accessors=[{"bufferView": 0, "componentType": 5126, "count": 2 ** 53, "type": "VEC3"}]), pos))
mesh_file("doubles.glb", glb(doc(accessors=[{"bufferView": 0, "componentType": 5130, "count": 3, "type": "VEC3"}]), pos))
mesh_file("vec2_positions.glb", glb(doc(accessors=[{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC2"}]), pos))
mesh_file("no_bin_chunk.glb", glb(doc(), None))
mesh_file("index_past_positions.glb", glb(doc(
    bufferViews=[{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 12}],
    buffers=[{"byteLength": 48}],
    accessors=[{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
               {"bufferView": 1, "componentType": 5125, "count": 3, "type": "SCALAR"}],
    meshes=[{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}]), pos + struct.pack("<3I", 0, 1, 7)))
mesh_file("mode_points.glb", glb(doc(meshes=[{"primitives": [{"attributes": {"POSITION": 0}, "mode": 0}]}]), pos))
mesh_file("accessor_cycle_ids.glb", glb(doc(meshes=[{"primitives": [{"attributes": {"POSITION": -1}}]}]), pos))
mesh_file("ten_thousand_primitives.glb", glb(doc(meshes=[{"primitives": [{"attributes": {"POSITION": 0}}] * 10000}]), pos))
os.symlink("loop_b.stl", "loop_a.stl"); os.symlink("loop_a.stl", "loop_b.stl")
scene("mesh file", "symlink_loop", 'scene { mesh("loop_a.stl"); }')
os.mkdir("dir.stl")
scene("mesh file", "directory_mesh", 'scene { mesh("dir.stl"); }')
scene("mesh file", "proc_file_mesh", 'scene { mesh("/proc/self/status.stl"); }')

# ---- text -------------------------------------------------------------------------------
scene("text", "newlines_only", 'scene { extrude(text("%s"), 0.1); }' % ("\\n" * 9999 + "a"))
scene("text", "no_glyph", 'scene { extrude(text("a\u0301\U0001F600"), 0.1); }')
scene("text", "tiny_size", 'scene { extrude(text("ab", 1e-300), 0.1); }')
scene("text", "huge_size", 'scene { extrude(text("ab", 1e300), 0.1); }')
scene("text", "font_dev_zero", 'scene { extrude(text("ab", 1, "/dev/zero"), 0.1); }')
scene("text", "font_directory", 'scene { extrude(text("ab", 1, "."), 0.1); }')
put("notafont.ttf", b"\0\1\0\0" + b"\xff" * 4096)
scene("text", "font_garbage", 'scene { extrude(text("ab", 1, "notafont.ttf"), 0.1); }')
scene("text", "texts_in_a_loop", 'scene { for i in 0..3 { extrude(text("%s"), 0.1).translate(i, 0, 0); } }' % ("W" * 4000))
scene("text", "text_in_a_function_memo", 'fn t(s: string) -> shape { extrude(text(s), 0.1) }\nscene { for i in 0..1000 { t("%s").translate(i, 0, 0); } }' % ("x" * 50))
render("text", "render_ten_thousand", 'scene { extrude(text("%s", 0.01), 0.1); }' % ("W" * 10000))

# ---- lists ------------------------------------------------------------------------------
scene("lists", "index_past_end", 'let xs = [1, 2];\nscene { sphere(xs[5]); }')
scene("lists", "negative_index", 'let xs = [1, 2];\nscene { sphere(xs[-1]); }')
scene("lists", "huge_index", 'let xs = [1, 2];\nscene { sphere(xs[1000000000000000000]); }')
scene("lists", "comprehension_100k", 'let xs = [for i in 0..100000 { i }];\nscene { sphere(len(xs)); }')
scene("lists", "nested_comprehension", 'let xs = [for i in 0..3000 { len([for j in 0..3000 { j }]) }];\nscene { sphere(len(xs)); }')
scene("lists", "empty_union", 'scene { union([]); }')
scene("lists", "union_of_50k", 'scene { union([for i in 0..50000 { sphere(0.1).translate(i, 0, 0) }]); }')
scene("lists", "list_equality", 'let a = [for i in 0..50000 { i }];\nscene { if a == a { sphere(1); } }')
scene("lists", "list_in_list_type", 'fn f(xs: [[float]]) -> float { 1 }\nscene { sphere(f([[1]])); }')
scene("lists", "index_by_float", 'let xs = [1, 2];\nscene { sphere(xs[0.5]); }')

# ---- fields -----------------------------------------------------------------------------
scene("fields", "divide_by_zero", 'scene { field { length(p) / 0 - 1 }; }')
scene("fields", "bool_body", 'scene { field { p.x > 0 }; }')
scene("fields", "w_component", 'scene { field { p.w }; }')
scene("fields", "nested_fields", 'scene { field { length(p) - 1 + 0 * %s0 %s }; }' % ("field { " * 200, "}" * 200))
scene("fields", "long_sum", 'scene { field { length(p) - 1%s }; }' % (" + p.x * 0" * 20000))
scene("fields", "sqrt_negative", 'scene { field { sqrt(-1 - length(p)) }; }')
scene("fields", "field_of_field_as_colour", 'material m = phong { color: field { field { vec3(1, 0, 0) } } };\nscene { sphere(1) @ m; }')
scene("fields", "deep_parentheses", 'scene { field { %slength(p)%s - 1 }; }' % ("(" * 900, ")" * 900))

# ---- profiles ---------------------------------------------------------------------------
scene("profiles", "tiny_circle", 'scene { extrude(circle(1e-300), 1); }')
scene("profiles", "huge_rect_revolved", 'scene { revolve(rect((1e300, 1))); }')
scene("profiles", "polygon_same_points", 'scene { extrude(polygon([(1, 1), (1, 1), (1, 1)]), 1); }')
scene("profiles", "polygon_comprehension_50k", 'let n = 50000;\nscene { extrude(polygon([for i in 0..n { (cos(i * 360deg / n), sin(i * 360deg / n)) }]), 1); }')
scene("profiles", "polygon_spiral_crossing", 'let n = 20000;\nscene { extrude(polygon([for i in 0..n { (cos(i * 7200deg / n) * i / n, sin(i * 7200deg / n) * i / n) }]), 1); }')
scene("profiles", "comb_polygon", 'let n = 20000;\nscene { extrude(polygon([for i in 0..n { (if i % 2 == 0 { 0 } else { 1 }, i / n) }]), 1); }')
scene("profiles", "star_thin", 'scene { extrude(star(10000, 1, 0.000001), 1); }')
scene("profiles", "screw_pitch_zero", 'scene { screw(circle(0.2).translate(1, 0), 0, 1); }')
scene("profiles", "loft_of_empty", 'scene { loft(intersect(circle(1), circle(1).translate(5, 0)), circle(1), 1); }')
scene("profiles", "offset_huge", 'scene { extrude(circle(1).offset(1e300), 1); }')

# ---- fmt --------------------------------------------------------------------------------
def fmt(name, data, *extra, stdin=False):
    put(name, data)
    if stdin:
        cases.append(("fmt", name + " (stdin)", ["fmt", *extra], data if isinstance(data, bytes) else data.encode(), False))
    else:
        cases.append(("fmt", name, ["fmt", *extra, name], None, False))
fmt("deep_parens.sdf", "let x = " + "(" * 100000 + "1" + ")" * 100000 + ";\n", "--check")
fmt("long_line.sdf", "let x = 1" + " + 1" * 500000 + ";\n", stdin=True)
fmt("many_comments.sdf", "// c\n" * 300000 + "let x = 1;\n", stdin=True)
fmt("unterminated_comment.sdf", "let x = 1; /* " + "a" * 100000, stdin=True)
fmt("crlf.sdf", "let x = 1;\r\nscene { sphere(x); }\r\n", stdin=True)
fmt("lone_cr.sdf", "let x = 1;\rscene { sphere(x); }\r", stdin=True)
fmt("not_utf8.sdf", b"let x = \xff;\n", stdin=True)
fmt("nul_bytes.sdf", b"let x\0 = 1;\n", stdin=True)
fmt("big_comment.sdf", "/*" + "x" * 20000000 + "*/\nlet x = 1;\n", stdin=True)
fmt("many_items.sdf", "".join("let a%d=sphere(1).translate(%d,0,0);\n" % (i, i) for i in range(100000)), stdin=True)
os.mkdir("fmtdir"); os.symlink("..", "fmtdir/up"); os.symlink("..", "fmtdir/up2"); os.mkfifo("fmtdir/pipe.sdf")
put("fmtdir/a.sdf", "let x=1;\n")
cases.append(("fmt", "directory_with_loop_and_fifo", ["fmt", "--check", "fmtdir"], None, False))

# ---- special files ----------------------------------------------------------------------
os.mkfifo("fifo.sdf")
cases.append(("special files", "fifo_scene", ["check", "fifo.sdf"], None, False))
cases.append(("special files", "dev_null_scene", ["check", "/dev/null"], None, False))
cases.append(("special files", "proc_status_scene", ["check", "/proc/self/status"], None, False))
put("imports_fifo.sdf", 'import "fifo.sdf";\nscene { sphere(1); }\n')
cases.append(("special files", "import_fifo", ["check", "imports_fifo.sdf"], None, False))
put("imports_urandom.sdf", 'import "/dev/urandom";\nscene { sphere(1); }\n')
cases.append(("special files", "import_urandom", ["check", "imports_urandom.sdf"], None, False))
os.symlink("self_link.sdf", "self_link.sdf")
cases.append(("special files", "symlink_to_itself", ["check", "self_link.sdf"], None, False))
cases.append(("special files", "fmt_dev_zero", ["fmt", "/dev/zero"], None, False))
cases.append(("special files", "mesh_scene_fifo", ["mesh", "fifo.sdf", "-o", "x.stl"], None, False))
cases.append(("special files", "render_to_dev_full", ["compile", "imports_urandom.sdf", "--emit", "wgsl", "-o", "/dev/full"], None, False))

# ---- lsp --------------------------------------------------------------------------------
def msg(o):
    b = json.dumps(o).encode()
    return b"Content-Length: %d\r\n\r\n" % len(b) + b
init = msg({"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": {"capabilities": {}}}) + \
    msg({"jsonrpc": "2.0", "method": "initialized", "params": {}})
end = msg({"jsonrpc": "2.0", "id": 999, "method": "shutdown"}) + msg({"jsonrpc": "2.0", "method": "exit"})
uri = "file://" + os.path.join(work, "doc.sdf")
def opened(text):
    return msg({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {"uri": uri, "languageId": "sdf", "version": 1, "text": text}}})
def req(i, method, params):
    return msg({"jsonrpc": "2.0", "id": i, "method": method, "params": params})
def at(line, ch):
    return {"textDocument": {"uri": uri}, "position": {"line": line, "character": ch}}
def lsp(name, middle):
    cases.append(("lsp", name, ["lsp"], init + middle + end, True))
lsp("plus_sign_length", b"Content-Length: +5\r\n\r\n{}{}{")
lsp("hex_length", b"Content-Length: 0x10\r\n\r\n" + b"{" * 16)
lsp("two_lengths", b"Content-Length: 2\r\nContent-Length: 40\r\n\r\n{}")
lsp("long_header_line", b"X-Junk: " + b"a" * 200000 + b"\r\nContent-Length: 2\r\n\r\n{}")
lsp("nested_json_body", msg(json.loads("[" * 100 + "]" * 100)) + (lambda b: b"Content-Length: %d\r\n\r\n" % len(b) + b)(b"[" * 100000 + b"]" * 100000))
big = "let a = 1;\n" * 400000 + "scene { sphere(a); }\n"
lsp("hover_far_past_the_end", opened(big) + req(2, "textDocument/hover", at(10 ** 9, 10 ** 9)))
lsp("change_past_the_end", opened("scene { sphere(1); }\n") + msg({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {"textDocument": {"uri": uri, "version": 2}, "contentChanges": [{"range": {"start": {"line": 50, "character": 0}, "end": {"line": 2, "character": 99}}, "text": "x"}]}}) + req(2, "textDocument/hover", at(0, 10)))
lsp("surrogate_half", opened("let s = \"\U0001F600\";\nscene { sphere(1); }\n") + req(2, "textDocument/completion", at(0, 10)) + req(3, "textDocument/hover", at(0, 10)))
lsp("untitled_uri", msg({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {"uri": "untitled:Untitled-1", "languageId": "sdf", "version": 1, "text": "scene { sphere(1); }"}}}) + req(2, "textDocument/documentSymbol", {"textDocument": {"uri": "untitled:Untitled-1"}}))
lsp("import_dev_zero", opened('import "/dev/zero";\nscene { sphere(1); }\n') + req(2, "textDocument/hover", at(1, 9)))
lsp("rename_megabyte", opened("let a = 1;\nscene { sphere(a); }\n") + req(2, "textDocument/rename", dict(at(0, 4), newName="b" * 1000000)))
lsp("cancel_and_unknown", msg({"jsonrpc": "2.0", "method": "$/cancelRequest", "params": {"id": 2}}) + req(3, "$/unknown", {}) + req(4, "textDocument/hover", None))
lsp("documents_by_the_thousand", b"".join(msg({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {"uri": uri + str(i), "languageId": "sdf", "version": 1, "text": "scene { sphere(%d); }" % (i + 1)}}}) for i in range(3000)))
lsp("text_past_the_limit", opened('scene { extrude(text("%s"), 0.1); }\n' % ("W" * 200000)) + req(2, "textDocument/hover", at(0, 20)))

# ---- run --------------------------------------------------------------------------------
held = failed = 0
for surface, name, argv, stdin, is_lsp in cases:
    t0 = time.time()
    cmd = ["/usr/bin/time", "-f", "%M", "-o", "time.out", sdfc, *argv]
    p = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        out, err = p.communicate(input=stdin if stdin is not None else b"", timeout=seconds)
        code, err = p.returncode, err.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        # The command and /usr/bin/time, its parent, are the one process group started here.
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        code, out, err = None, b"", ""
    dt = time.time() - t0
    try:
        kb = int(open("time.out").read().split()[-1])
    except Exception:
        kb = 0
    why = None
    if code is None:
        why = "hang (over %g s)" % seconds
    elif "panicked" in err or code == 101:
        why = "panic"
    elif code < 0 or code > 2:
        why = "exit %d (a signal or abort)" % code
    elif code != 0 and not err.strip():
        why = "silent exit %d" % code
    elif kb > mib * 1024:
        why = "memory %d MiB" % (kb // 1024)
    elif is_lsp and (code != 0 or b'"id":999' not in out.replace(b" ", b"")):
        why = "the server stopped serving (exit %s)" % code
    if why:
        failed += 1
    else:
        held += 1
    print("%-6s %-14s %-34s exit %-4s %6.2f s %5d MiB%s" % ("held" if not why else "FAILED", surface, name, code, dt, kb // 1024, "  " + why if why else ""), flush=True)
try:
    os.remove("time.out")
except OSError:
    pass
print("inputs %d, held %d, failed %d" % (held + failed, held, failed))
sys.exit(1 if failed else 0)
PY
