"""The layer order of docs/architecture.md, checked on every include in server/.

A folder uses only the folders below it in ORDER. Inside render/, the rooms have an order too:
cpu/ (what runs without GL: geometry, layers, cameras, light, the interface shared with GLSL) uses
nothing else of render/ and no GL; gl/ (the GL plumbing) uses only itself and cpu/.
Prints each include that breaks a rule and exits 1 if any does.
"""
import pathlib
import re
import sys

ORDER = ["app", "rpc", "session", "render", "model", "sim", "road", "encode"]
# What each room of render/ may include of render/.
ROOMS = {"render/gl": {"render/gl", "render/cpu"}, "render/cpu": {"render/cpu"}}
GL_HEADERS = re.compile(r"#include\s*[<\"](GL/|EGL/|epoxy/|server/render/gl/gl\.hpp)")
INCLUDE = re.compile(r'#include\s*"server/([a-z_]+)/([^"]+)"')


def main(root):
    server = pathlib.Path(root) / "server"
    breaches = []
    for path in sorted(server.rglob("*.[ch]pp")):
        parts = path.relative_to(server).parts
        layer = parts[0]
        room = "/".join(parts[:2]) if len(parts) > 2 else None
        text = path.read_text(encoding="utf-8")
        for n, line in enumerate(text.splitlines(), 1):
            m = INCLUDE.match(line.strip())
            if m:
                target, rest = m.group(1), m.group(2)
                if layer in ORDER and target in ORDER and ORDER.index(target) < ORDER.index(layer):
                    breaches.append(f"{path}:{n}: {layer}/ includes {target}/ above it: {line.strip()}")
                if room in ROOMS and target == "render":
                    target_room = "render/" + rest.split("/")[0] if "/" in rest else "render"
                    if target_room not in ROOMS[room]:
                        breaches.append(f"{path}:{n}: {room}/ includes {target_room}/: {line.strip()}")
            if room == "render/cpu" and GL_HEADERS.match(line.strip()):
                breaches.append(f"{path}:{n}: render/cpu/ includes GL: {line.strip()}")
    for b in breaches:
        print(b)
    print(f"{len(breaches)} includes against the layer order")
    return 1 if breaches else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
