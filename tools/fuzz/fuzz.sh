#!/usr/bin/env bash
# Fuzzes the glTF loader with libFuzzer for SECONDS (default 600): builds build-fuzz/ with clang
# (ASan + UBSan), gathers a seed corpus, and runs until the time is up or a finding. With
# `formats`, fuzzes the files pathreuse derives and reads back instead: the kernel cache's and
# the resume history's formats (tools/fuzz/format_fuzzer.cpp); `cache` or `history`, one of them.
#   bash tools/fuzz/fuzz.sh [SECONDS] [gltf|formats|cache|history]
# Needs clang with libFuzzer (Debian 12: apt-get install clang libclang-rt-14-dev); not in
# tools/setup/install-deps.sh, which installs what the build and the tests need, and nothing more.
# The corpus grows in out/fuzz-corpus/ across runs; findings land in out/fuzz-findings/
# (crash-*, timeout-*, oom-*). Reproduce one: build-fuzz/gltf_fuzzer FILE.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds="${1:-600}"
target="${2:-gltf}"
jobs="${JOBS:-$(nproc)}"
if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: clang++ not found; install it: apt-get install clang libclang-rt-14-dev" >&2
  exit 2
fi

CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPATHREUSE_FUZZ=ON \
  -DPATHREUSE_TESTS=OFF -DPATHREUSE_TOOLS=OFF >/dev/null
if [ "$target" = formats ] || [ "$target" = cache ] || [ "$target" = history ]; then
  cmake --build build-fuzz --target format_fuzzer -j"$jobs"
  seeds=out/fuzz-format-seeds corpus=out/fuzz-$target-corpus findings=out/fuzz-format-findings
  mkdir -p "$seeds" "$corpus" "$findings"
  only=$([ "$target" = formats ] || echo "$target")
  FORMAT_FUZZER_ONLY="$only" FORMAT_FUZZER_SEEDS="$seeds" ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}" \
    UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}" \
    build-fuzz/format_fuzzer "$corpus" "$seeds" -max_total_time="$seconds" -max_len=16384 \
    -rss_limit_mb=2048 -timeout=10 -artifact_prefix="$findings/" -print_final_stats=1
  exit
fi
[ "$target" = gltf ] || { echo "fuzz.sh: no target '$target' (gltf, formats, cache, history)" >&2; exit 2; }
cmake --build build-fuzz --target gltf_fuzzer -j"$jobs"

# Seeds: our scenes, the shared real and broken files, Debian's assimp glTF models, each up to
# 64 KiB, with external buffers and images embedded as data: URIs so they load from memory.
seeds=out/fuzz-seeds corpus=out/fuzz-corpus findings=out/fuzz-findings
mkdir -p "$seeds" "$corpus" "$findings"
python3 - "$seeds" scenes ../shared/scenes /usr/share/assimp/models/glTF2 <<'PY'
import base64, glob, hashlib, json, os, sys
out, roots = sys.argv[1], sys.argv[2:]
def embed(path):
    text = open(path, 'rb').read()
    if not path.endswith('.gltf'):
        return text
    try:
        doc = json.loads(text)
    except Exception:
        return text
    base = os.path.dirname(path)
    for kind in ('buffers', 'images'):
        for item in doc.get(kind, []) if isinstance(doc.get(kind), list) else []:
            uri = item.get('uri') if isinstance(item, dict) else None
            f = os.path.join(base, uri) if isinstance(uri, str) and not uri.startswith('data:') else None
            if f and os.path.isfile(f) and os.path.getsize(f) < 48 * 1024:
                item['uri'] = 'data:application/octet-stream;base64,' + base64.b64encode(open(f, 'rb').read()).decode()
    return json.dumps(doc, separators=(',', ':')).encode()
for root in roots:
    for path in glob.glob(os.path.join(root, '**', '*.gl*'), recursive=True):
        if not path.endswith(('.gltf', '.glb')) or os.path.getsize(path) > 64 * 1024:
            continue
        data = embed(path)
        if len(data) <= 64 * 1024:
            open(os.path.join(out, hashlib.sha1(data).hexdigest()), 'wb').write(data)
PY

ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}" UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}" \
  build-fuzz/gltf_fuzzer "$corpus" "$seeds" -dict=tools/fuzz/gltf.dict \
  -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -malloc_limit_mb=1024 -timeout=10 \
  -artifact_prefix="$findings/" -print_final_stats=1
