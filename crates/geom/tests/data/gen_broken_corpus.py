import struct, os
B='broken/'
def w(name, data):
    mode = 'wb' if isinstance(data, bytes) else 'w'
    with open(B+name, mode) as f: f.write(data)

cube = [((i&1)*2.0, ((i>>1)&1)*2.0, ((i>>2)&1)*2.0) for i in range(8)]
cube_faces = [(0,2,3,1),(4,5,7,6),(0,1,5,4),(2,6,7,3),(0,4,6,2),(1,3,7,5)]
def fan(f): return [(f[0],f[k],f[k+1]) for k in range(1,len(f)-1)]
cube_tris = [t for f in cube_faces for t in fan(f)]
dent_pts = cube + [(1.0,1.0,1.0)]
dent_faces = [f for f in cube_faces if f != (4,5,7,6)] + [(4,5,8),(5,7,8),(7,6,8),(6,4,8)]
dent_tris = [t for f in dent_faces for t in fan(f)]
tet = [(0.0,0.0,0.0),(1.0,0.0,0.0),(0.0,1.0,0.0),(0.0,0.0,1.0)]
tet_tris = [(0,2,1),(0,1,3),(0,3,2),(1,2,3)]

def ascii_stl(name, pts, tris, vertex_fmt=None):
    s = f"solid {name}\n"
    for t in tris:
        s += "  facet normal 0 0 0\n    outer loop\n"
        for v in t:
            p = pts[v]
            s += "      vertex %r %r %r\n" % p
        s += "    endloop\n  endfacet\n"
    return s + f"endsolid {name}\n"

def bin_stl(pts, tris, header=b"binary test", count=None):
    h = header.ljust(80, b'\0')
    out = h + struct.pack('<I', len(tris) if count is None else count)
    for t in tris:
        out += struct.pack('<3f', 0, 0, 0)
        for v in t: out += struct.pack('<3f', *pts[v])
        out += b'\0\0'
    return out

# binary STL
full = bin_stl(tet, tet_tris)
w('stl_binary_truncated.stl', bin_stl(tet, tet_tris[:1], count=2) + full[84:104])       # 84+50+20 bytes, header says 2
w('stl_binary_padded.stl', bin_stl(tet, tet_tris) + b'\0'*7)                           # 7 extra bytes
w('stl_binary_solid_header_truncated.stl', bin_stl(tet, tet_tris, header=b"solid exported")[:-30])
w('stl_binary_short_header.stl', b"\0binary"*5)                                            # 5 bytes, no count
nan = bytearray(bin_stl(tet, tet_tris))
nan[84+12+12*1+4:84+12+12*1+8] = struct.pack('<f', float('nan'))                        # triangle 0, vertex 1, y
w('stl_binary_nan.stl', bytes(nan))
# ASCII STL
s = ascii_stl('t', tet, tet_tris).split('\n'); s[3] = "      vertex nan 0 0"; w('stl_ascii_nan.stl', '\n'.join(s))
s = ascii_stl('t', tet, tet_tris).split('\n'); s[4] = "      vertex 1.0 abc 0"; w('stl_ascii_bad_number.stl', '\n'.join(s))
w('stl_ascii_truncated.stl', '\n'.join(ascii_stl('t', tet, tet_tris).split('\n')[:12]) + '\n')
w('stl_ascii_open_shell.stl', ascii_stl('open', tet, tet_tris[:3]))
w('stl_ascii_nonconvex.stl', ascii_stl('dent', dent_pts, dent_tris))
w('stl_ascii_flat.stl', ascii_stl('flat', tet, [(0,1,2),(0,2,1)]))
w('stl_ascii_inverted.stl', ascii_stl('inside_out', tet, [(a,c,b) for (a,b,c) in tet_tris]))
w('stl_ascii_empty.stl', "solid nothing\nendsolid nothing\n")
w('stl_ascii_four_vertices.stl', "solid q\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid q\n")
w('stl_ascii_huge.stl', ascii_stl('t', tet, tet_tris).replace("vertex 1.0 0.0 0.0", "vertex 1e400 0.0 0.0", 1))

# OBJ
def obj(groups, pts):
    s = "# test\n" + "".join("v %r %r %r\n" % p for p in pts)
    for name, faces in groups:
        if name: s += f"g {name}\n"
        for f in faces: s += "f " + " ".join(str(i+1) for i in f) + "\n"
    return s
w('obj_bad_index.obj', "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 9\n")
w('obj_zero_index.obj', "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")
w('obj_negative_out_of_range.obj', "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -7\n")
w('obj_bad_number.obj', "v 0 0 0\nv 1.0 x 2\n")
w('obj_short_face.obj', "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n")
w('obj_missing_coordinate.obj', "v 0 0 0\nv 1 2\n")
w('obj_nan.obj', "v 0 0 0\nv 1 0 0\nv NaN 1 0\nv 0 0 1\nf 1 3 2\n")
w('obj_no_faces.obj', "# only vertices\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")
w('obj_bad_reference.obj', "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2//x 3\n")
pts = tet + [(p[0]+5, p[1], p[2]) for p in dent_pts]
w('obj_nonconvex_group.obj', obj([('tetra', tet_tris), ('dented_cube', [tuple(v+4 for v in f) for f in dent_faces])], pts))
w('obj_degenerate_group.obj', "v 0 0 0\nv 1 0 0\nv 0 1 0\no flat\nf 1 2 3\nf 1 3 2\n")

# JSON
w('json_missing_thickness.json', '{"name": "m",\n "sheet_metal": {\n   "faces": [{"outline": [[0,0,0],[10,0,0],[10,10,0],[0,10,0]]}]\n }\n}\n')
w('json_thickness_zero.json', '{"name": "z", "sheet_metal": {"thickness": 0, "faces": [{"outline": [[0,0,0],[10,0,0],[10,10,0],[0,10,0]]}]}}\n')
w('json_nonplanar_face.json', '{"name": "np", "sheet_metal": {"thickness": 1, "faces": [\n  {"outline": [[0,0,0],[10,0,0],[10,10,0],[0,10,0]]},\n  {"outline": [[0,0,0],[0,10,0],[0,10,10],[0,0,10],[0,-5,5]]},\n  {"outline": [[0,0,0],[10,0,0],[10,0,10],[3,1,10],[0,0,10]]}\n]}}\n')
w('json_hole_outside.json', '{"name": "h", "sheet_metal": {"thickness": 1, "faces": [{"outline": [[0,0,0],[10,0,0],[10,10,0],[0,10,0]], "holes": [[[20,20,0],[22,20,0],[22,22,0]]]}]}}\n')
w('json_nan.json', '{"name": "n", "convex_pieces": [[[0,0,0],[1,0,0],[0,1,0],[0,0,NaN]]]}\n')
w('json_huge_number.json', '{"name": "big",\n "convex_pieces": [[[0,0,0],[1,0,0],[0,1,0],[0,0,1e400]]]}\n')
w('json_empty_pieces.json', '{"name": "e", "convex_pieces": []}\n')
w('json_degenerate_piece.json', '{"name": "d", "convex_pieces": [\n  [[0,0,0],[1,0,0],[0,1,0],[0,0,1]],\n  [[0,0,5],[1,0,5],[0,1,5],[1,1,5]]\n]}\n')
w('json_unknown_key.json', '{"name": "u", "convex_piece": [[[0,0,0],[1,0,0],[0,1,0],[0,0,1]]]}\n')
w('json_both_forms.json', '{"name": "b", "convex_pieces": [[[0,0,0],[1,0,0],[0,1,0],[0,0,1]]], "sheet_metal": {"thickness": 1, "faces": [{"outline": [[0,0,0],[10,0,0],[10,10,0]]}]}}\n')
w('json_neither_form.json', '{"name": "nothing", "density": 2.0}\n')
w('json_negative_density.json', '{"name": "neg", "density": -1, "convex_pieces": [[[0,0,0],[1,0,0],[0,1,0],[0,0,1]]]}\n')
w('json_coordinate_too_large.json', '{"name": "far", "convex_pieces": [[[0,0,0],[1,0,0],[0,1,0],[0,0,1]], [[0,0,0],[1,0,0],[0,1,0],[0,0,1e12]]]}\n')
w('json_truncated.json', '{"name": "t", "convex_pieces": [[[0,0,0],[1,0,0],[0,1,0],\n')
w('json_wrong_point_length.json', '{"name": "p",\n "convex_pieces": [[[0,0,0],[1,0],[0,1,0],[0,0,1]]]}\n')
w('json_no_faces.json', '{"name": "nf", "sheet_metal": {"thickness": 1, "faces": []}}\n')
w('json_self_intersecting.json', '{"name": "bow", "sheet_metal": {"thickness": 1, "faces": [{"outline": [[0,0,0],[10,10,0],[10,0,0],[0,20,0]]}]}}\n')
# stack files
w('stack_reflection.json', '{"part": {"name": "t", "convex_pieces": [[[0,0,0],[1,0,0],[0,1,0],[0,0,1]]]},\n "placements": [\n  {"position": [0,0,0], "rotation": [[1,0,0],[0,1,0],[0,0,1]]},\n  {"position": [0,0,5], "rotation": [[1,0,0],[0,1,0],[0,0,-1]]}\n]}\n')
w('stack_missing_part_file.json', '{"part": "no_such_part.json", "placements": []}\n')
w('stack_bad_inline_part.json', '{"part": {"name": "e", "convex_pieces": []}, "placements": []}\n')
w('stack_unknown_key.json', '{"part": "x.json", "placement": []}\n')

# valid seeds (tests/data/good): mutated by the no-panic proptest and used as fuzz seeds
G = 'good/'
os.makedirs(G, exist_ok=True)
def g(name, data):
    with open(G+name, 'wb' if isinstance(data, bytes) else 'w') as f: f.write(data)
g('cube.stl', ascii_stl('cube', cube, cube_tris))
g('tetra_binary.stl', bin_stl(tet, tet_tris, header=b"solid tetra (binary)"))
g('two_groups.obj', obj([('tetra', tet_tris), ('cube', [tuple(v+4 for v in f) for f in cube_faces])], tet + [(p[0]+5, p[1], p[2]) for p in cube]))
g('pieces.json', '{"name": "pieces", "density": 2.5, "convex_pieces": [[[0,0,0],[1,0,0],[0,1,0],[0,0,1]], [[5,0,0],[7,0,0],[5,2,0],[7,2,0],[5,0,2],[7,0,2],[5,2,2],[7,2,2]]]}\n')
g('sheet.json', '{"name": "plate", "sheet_metal": {"thickness": 1.5, "faces": [{"outline": [[0,0,0],[30,0,0],[30,20,0],[0,20,0]], "holes": [[[5,5,0],[10,5,0],[10,10,0],[5,10,0]]]}, {"outline": [[0,0,2],[0,20,2],[0,20,25],[0,0,25]]}]}}\n')
g('stack.json', '{"part": "pieces.json", "placements": [{"position": [0,0,0], "rotation": [[1,0,0],[0,1,0],[0,0,1]]}, {"position": [0,0,3], "rotation": [[0,-1,0],[1,0,0],[0,0,1]], "cost": 1.5}]}\n')
