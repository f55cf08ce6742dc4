#!/usr/bin/env python3
"""Times a copy of a compiled inner loop on its own, optionally edited.

Without hardware counters, the way to learn what an instruction costs inside a
hot loop is to take the loop out of the binary, time it alone, and time it
again with that instruction removed or replaced. This script extracts the
innermost loop of a function that contains a given instruction (objdump),
builds a C++ harness around it (every vector register and the loop's base
registers start from a buffer of small random floats, mask registers all
ones), compiles it with -march=native and prints cycles per iteration,
against a dependent-add clock calibration taken in the same process.
x86-64 with AVX-512 (the harness sets all 32 zmm registers); the loop must
be straight-line code that steps a pointer and ends in cmp + jne.

Edits drop or rewrite lines before timing; a removed instruction must not
leave a value to be carried from one iteration to the next, or the copy
measures a dependency chain instead (removing blends or compares is safe,
removing an FMA usually is not).

Example (docs/kernels.md, "Speed-ups over width 1"):
  scripts/loop_replica.py build/bench/raypack_bench \\
      'triangle_packet<(raypack::TriangleMethod)0, 16>' --contains vdivps \\
      --drop '\\{%k1\\}$'
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

BRANCHES = ("jne", "jnz", "jb", "jae", "jbe", "ja", "jl", "jge", "jle", "jg")


def function_lines(binary, symbol):
    out = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "-C", binary], capture_output=True, text=True,
                         check=True).stdout.split("\n")
    header = re.compile(r"^[0-9a-f]+ <(.*)>:$")
    lines, names, inside = [], [], False
    for line in out:
        m = header.match(line)
        if m:
            inside = symbol in m.group(1) and "[clone" not in m.group(1)
            if inside:
                names.append(m.group(1))
            continue
        if inside and line.strip():
            lines.append(line)
    if len(names) > 1:
        sys.exit("loop_replica: '{}' names {} functions, e.g.\n  {}".format(symbol, len(names), "\n  ".join(names[:5])))
    return lines


def innermost_loop(lines, contains):
    parsed = []
    for line in lines:
        m = re.match(r"\s*([0-9a-f]+):\s*(.*)", line)
        if m:
            parsed.append((int(m.group(1), 16), m.group(2).split("#")[0].strip()))
    best = None
    for addr, ins in parsed:
        op = ins.split()[0] if ins else ""
        if op in BRANCHES:
            target = int(ins.split()[1], 16)
            if target < addr:
                body = [i for a, i in parsed if target <= a <= addr]
                if any(contains in i for i in body) and (best is None or len(body) < len(best)):
                    best = body
    return best


def general_registers(body):
    """The 64-bit names of every general register the loop mentions, to declare them clobbered."""
    names = set()
    for ins in body:
        for r in re.findall(r"%([a-z0-9]+)", ins):
            m = re.fullmatch(r"r(\d+)[dwb]?", r)
            if m:
                names.add("r" + m.group(1))
                continue
            m = re.fullmatch(r"[re]?([abcd])[xlh]|[re]?(si|di|bp|sp)l?", r)
            if m:
                names.add("r" + (m.group(1) + "x" if m.group(1) else m.group(2)))
    names.discard("rsp")
    return sorted(names)


def harness(body, calibration_adds=1 << 22):
    """C++ source that runs `body` (a loop ending in cmp + branch) and prints cycles per iteration."""
    branch = body[-1]
    cmp = body[-2]
    adds = [i for i in body if re.match(r"(add|sub|lea)\s", i) and re.search(r"%r\w+$", i)]
    if not cmp.startswith("cmp") or not adds:
        sys.exit("loop_replica: expected a loop that steps a pointer (add) and ends in cmp + branch")
    step_ins = adds[0]
    m = re.match(r"add\s+\$0x([0-9a-f]+),(%r\w+)", step_ins)
    if not m:
        sys.exit(f"loop_replica: cannot read the pointer step from '{step_ins}'")
    stride, ptr = int(m.group(1), 16), m.group(2)
    regs = re.findall(r"%r\w+", cmp)
    if ptr not in regs or not branch.startswith(("jne", "jnz")):
        sys.exit(f"loop_replica: the loop does not end by comparing its stepped pointer {ptr} for equality")
    end = [r for r in regs if r != ptr]
    if len(end) != 1:
        sys.exit(f"loop_replica: cannot find the end register in '{cmp}'")
    end = end[0]
    gprs = sorted({r for i in body for r in re.findall(r"\((%r\w+)", i)} - {ptr})
    iterations = 32
    buf_floats = (iterations * stride + 8192) // 4
    asm_text = "".join('      "{}\\n"\n'.format(i.replace("%", "%%").replace("{", "%{").replace("}", "%}"))
                       for i in body[:-1])
    init = "".join(f'      "vbroadcastss {4 * r}(%[buf]), %%zmm{r}\\n"\n' for r in range(32))
    init += "".join(f'      "kxnorw %%k{k}, %%k{k}, %%k{k}\\n"\n' for k in range(1, 8))
    init += "".join(f'      "lea 4096(%[buf]), %%{g[1:]}\\n"\n' for g in gprs)
    clobbers = ", ".join(f'"xmm{r}"' for r in range(32))
    gpr_clobbers = ", ".join(f'"{r}"' for r in sorted(set(general_registers(body)) | {ptr[1:], end[1:]}))
    return f"""#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
alignas(64) static float buf[{buf_floats}];
static double calibrate() {{
  unsigned long x = 1;
  const auto t0 = std::chrono::steady_clock::now();
  for (long i = 0; i < {calibration_adds}; i += 8)
    asm volatile("add %0,%0\\nadd %0,%0\\nadd %0,%0\\nadd %0,%0\\nadd %0,%0\\nadd %0,%0\\nadd %0,%0\\nadd %0,%0" : "+r"(x));
  return {calibration_adds} / std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}}
int main() {{
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  for (float& f : buf) f = u(rng);
  double best = 1e30, hz = 0;
  for (int rep = 0; rep < 15; ++rep) {{
    hz = std::max(hz, calibrate());
    const long outer = 200000;
    const auto t0 = std::chrono::steady_clock::now();
    for (long o = 0; o < outer; ++o) {{
      asm volatile(
{init}      "lea 4096(%[buf]), %%{ptr[1:]}\\n"
      "lea {4096 + iterations * stride}(%[buf]), %%{end[1:]}\\n"
      "1:\\n"
{asm_text}      "{branch.split()[0]} 1b\\n"
      :: [buf] "r"(buf) : {gpr_clobbers}, "k1", "k2", "k3", "k4", "k5", "k6", "k7", "cc", "memory", {clobbers});
    }}
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / (outer * {iterations}.0);
    best = std::min(best, s);
  }}
  std::printf("%.2f cycles per iteration (%.3f ns at %.2f GHz)\\n", best * hz, best * 1e9, hz / 1e9);
}}
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binary")
    ap.add_argument("symbol", help="a substring of the demangled function name")
    ap.add_argument("--contains", default="", help="the loop must contain this text (e.g. vdivps)")
    ap.add_argument("--drop", action="append", default=[], help="regex: drop matching instructions")
    ap.add_argument("--sub", action="append", default=[], nargs=2, metavar=("REGEX", "REPL"),
                    help="rewrite matching text in every instruction")
    ap.add_argument("--print", action="store_true", help="print the loop as timed")
    args = ap.parse_args()
    lines = function_lines(args.binary, args.symbol)
    if not lines:
        sys.exit(f"loop_replica: no function matching '{args.symbol}' in {args.binary}")
    body = innermost_loop(lines, args.contains)
    if not body:
        sys.exit(f"loop_replica: no loop containing '{args.contains}' in that function")
    if any(re.match(r"(j\w+|call|ret)\b", ins) for ins in body[:-1]):
        sys.exit("loop_replica: the loop branches inside; only straight-line loops can be copied")
    edited = []
    for ins in body:
        if any(re.search(d, ins) for d in args.drop):
            continue
        for pattern, repl in args.sub:
            ins = re.sub(pattern, repl, ins)
        edited.append(ins)
    if args.print:
        print("\n".join(edited))
    with tempfile.TemporaryDirectory() as tmp:
        src, exe = os.path.join(tmp, "replica.cpp"), os.path.join(tmp, "replica")
        with open(src, "w") as f:
            f.write(harness(edited))
        subprocess.run(["g++", "-O2", "-march=native", src, "-o", exe], check=True)
        try:
            print(subprocess.run([exe], capture_output=True, text=True, check=True, timeout=120).stdout, end="")
        except subprocess.TimeoutExpired:
            sys.exit("loop_replica: the copy ran for over 2 minutes; is the loop's exit condition what this script assumes?")


if __name__ == "__main__":
    main()
