# SPDX-License-Identifier: MIT
"""Keeps the README and the guide honest.

  check_docs.py style SOURCE_DIR
      no paragraph of README.md or a guide page is longer than 8 lines; README.md at most 200.
  check_docs.py examples SOURCE_DIR --cxx CXX --flags "..." --tools DIR [DIR ...]
                [--python PY --pythonpath DIR]
      every ```cpp block compiles; every ```python block runs (with --python); every --option
      a ```sh block gives a taxel tool is one its --help lists; every ```sh block that runs a
      taxel tool by name runs, in an empty folder with the tools on PATH.
  check_docs.py links SOURCE_DIR --chromium CHROMIUM --work DIR
      each page, rendered to HTML, loads in headless Chromium, and every relative link in the
      page Chromium read leads to an existing file and, for #anchors, an existing heading.
"""
import argparse
import concurrent.futures
import html
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

# Pages that measure rather than guide: long tables and lab notes are allowed there.
MEASUREMENT_PAGES = {"fusion-study.md", "recognition-study.md", "active-touch-study.md", "performance.md"}
MAX_PARAGRAPH_LINES = 8
MAX_README_LINES = 200
TOOL = re.compile(r"^(taxel-[a-z]+|[0-9][0-9]_[a-z_]+)$")


def pages(root):
    return [root / "README.md"] + sorted((root / "docs").glob("*.md"))


def blocks(text):
    """(language, first line number, code) of every fenced block."""
    out, lang, start, code = [], None, 0, []
    for n, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            if lang is None:
                lang, start, code = line[3:].strip() or "text", n + 1, []
            else:
                out.append((lang, start, "\n".join(code) + "\n"))
                lang = None
        elif lang is not None:
            code.append(line)
    return out


def check_style(root):
    errors = []
    for page in pages(root):
        lines = page.read_text().splitlines()
        if page.name == "README.md" and page.parent == root and len(lines) > MAX_README_LINES:
            errors.append(f"README.md: {len(lines)} lines, more than {MAX_README_LINES}")
        if page.name in MEASUREMENT_PAGES:
            continue
        fenced, run, start = False, 0, 0
        for n, line in enumerate(lines + [""], 1):
            if line.startswith("```"):
                fenced, run = not fenced, 0
                continue
            starts_item = re.match(r"^\s*([-*]|\d+\.)\s", line) is not None
            if fenced or not line.strip() or line.startswith(("|", "#")) or starts_item:
                if run > MAX_PARAGRAPH_LINES:
                    errors.append(f"{page.relative_to(root)}:{start}: a paragraph of {run} lines")
                run = 1 if starts_item and not fenced else 0
                start = n
                continue
            if run == 0:
                start = n
            run += 1
    return errors


def tool_commands(code):
    """(tool, arguments) of each command in a shell block that runs a taxel tool."""
    for line in code.splitlines():
        line = line.split(" #", 1)[0]
        for segment in re.split(r"\|\||&&|\||;", line):
            try:
                words = shlex.split(segment, comments=True)
            except ValueError:
                continue
            if words and TOOL.match(os.path.basename(words[0])):
                yield words[0], words[1:]


def check_examples(root, cxx, flags, tool_dirs, python):
    errors = []
    work = pathlib.Path(tempfile.mkdtemp(prefix="taxel-doc-examples-"))
    env = dict(os.environ, PATH=os.pathsep.join(map(str, tool_dirs)) + os.pathsep + os.environ["PATH"])
    compile_jobs, helps = [], {}

    def find_tool(name):
        for d in tool_dirs:
            if (pathlib.Path(d) / name).exists():
                return pathlib.Path(d) / name
        return None

    for page in pages(root):
        rel = page.relative_to(root)
        for k, (lang, line, code) in enumerate(blocks(page.read_text())):
            where = f"{rel}:{line}"
            if lang == "cpp":
                src = work / f"{rel.stem}_{k}.cpp"
                src.write_text(f"#line {line} \"{rel}\"\n" + code)
                compile_jobs.append((where, [cxx, *flags, "-fsyntax-only", str(src)]))
            elif lang == "python" and python:
                run = subprocess.run([python, "-c", code], cwd=work, env=env, capture_output=True,
                                     text=True, timeout=300)
                if run.returncode != 0:
                    errors.append(f"{where}: the Python block fails:\n{run.stderr[-2000:]}")
            elif lang == "sh":
                runnable = False
                for tool, args in tool_commands(code):
                    name = os.path.basename(tool)
                    path = find_tool(name)
                    if path is None:
                        errors.append(f"{where}: {name} is not a built tool or example")
                        continue
                    if name not in helps:
                        h = subprocess.run([str(path), "--help"], capture_output=True, text=True)
                        helps[name] = h.stdout + h.stderr
                    for a in args:
                        option = a.strip("[]").split("=", 1)[0]
                        listed = re.search(re.escape(option) + r"(?![\w-])", helps[name])
                        if option.startswith("--") and len(option) > 2 and not listed:
                            errors.append(f"{where}: {name} has no option {option} (see {name} --help)")
                    runnable = runnable or tool == name
                if runnable:
                    folder = work / f"sh_{rel.stem}_{k}"
                    folder.mkdir()
                    run = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", code], cwd=folder,
                                         env=env, capture_output=True, text=True, timeout=300)
                    if run.returncode != 0:
                        errors.append(f"{where}: the shell block exits {run.returncode}:\n"
                                      f"{run.stderr[-2000:]}")

    def compile_one(job):
        where, cmd = job
        r = subprocess.run(cmd, capture_output=True, text=True)
        return where, r.returncode, r.stderr

    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        for where, rc, err in pool.map(compile_one, compile_jobs):
            if rc != 0:
                errors.append(f"{where}: the C++ block does not compile:\n{err[-3000:]}")
    if not compile_jobs:
        errors.append("no C++ block found: the extraction is broken")
    shutil.rmtree(work, ignore_errors=True)
    return errors


def github_slug(text, seen):
    """The anchor GitHub gives a heading."""
    slug = re.sub(r"[^\w\- ]", "", html.unescape(re.sub(r"<[^>]+>", "", text)).lower()).replace(" ", "-")
    n = seen.get(slug, 0)
    seen[slug] = n + 1
    return slug if n == 0 else f"{slug}-{n}"


def check_links(root, chromium, work):
    import markdown  # Debian python3-markdown

    errors = []
    work = pathlib.Path(work)
    shutil.rmtree(work, ignore_errors=True)
    site = work / "site"
    dom_of = {}
    for page in pages(root):
        rel = page.relative_to(root)
        out = (site / rel).with_suffix(".html")
        out.parent.mkdir(parents=True, exist_ok=True)
        seen = {}
        md = markdown.Markdown(extensions=["fenced_code", "tables", "toc"],
                               extension_configs={"toc": {"slugify": lambda t, s: github_slug(t, seen)}})
        body = md.convert(page.read_text())
        out.write_text(f"<!doctype html><meta charset=utf-8><title>{rel}</title>{body}\n")
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             f"--user-data-dir={work / 'profile'}"]
    for page in pages(root):
        rel = page.relative_to(root)
        url = (site / rel).with_suffix(".html").resolve().as_uri()
        r = subprocess.run([chromium, *flags, "--dump-dom", url], capture_output=True, text=True,
                           timeout=120)
        if r.returncode != 0 or "<body" not in r.stdout:
            errors.append(f"{rel}: Chromium could not load it ({r.returncode}): {r.stderr[-500:]}")
            continue
        dom_of[rel] = r.stdout
    ids = {rel: set(re.findall(r'\sid="([^"]+)"', dom)) for rel, dom in dom_of.items()}
    for rel, dom in dom_of.items():
        refs = re.findall(r'<a\s[^>]*href="([^"]+)"', dom) + re.findall(r'<img\s[^>]*src="([^"]+)"', dom)
        for href in refs:
            href = html.unescape(href)
            if re.match(r"^[a-z]+:", href):
                continue  # http:, https:, mailto: are not ours to check here
            path, _, anchor = href.partition("#")
            target = (root / rel).parent / path if path else root / rel
            target = pathlib.Path(os.path.normpath(target))
            if not target.exists():
                errors.append(f"{rel}: the link {href} leads to a missing file")
                continue
            if anchor:
                trel = target.relative_to(root)
                if trel.suffix != ".md":
                    errors.append(f"{rel}: the link {href} has an anchor into a file that is not a page")
                elif trel not in ids:
                    errors.append(f"{rel}: the link {href} leads to a page that is not checked")
                elif anchor not in ids[trel]:
                    errors.append(f"{rel}: the link {href} names no heading of {trel}")
    return errors


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("what", choices=["style", "examples", "links"])
    ap.add_argument("root", type=pathlib.Path)
    ap.add_argument("--cxx")
    ap.add_argument("--flags", default="")
    ap.add_argument("--tools", nargs="*", default=[])
    ap.add_argument("--python")
    ap.add_argument("--pythonpath", default="", help="where the taxel package is built")
    ap.add_argument("--chromium")
    ap.add_argument("--work")
    a = ap.parse_args()
    root = a.root.resolve()
    if a.what == "style":
        errors = check_style(root)
    elif a.what == "examples":
        if a.pythonpath:
            os.environ["PYTHONPATH"] = str(pathlib.Path(a.pythonpath).resolve())
        tools = [pathlib.Path(t).resolve() for t in a.tools]
        errors = check_examples(root, a.cxx, shlex.split(a.flags), tools, a.python)
    else:
        errors = check_links(root, a.chromium, a.work)
    for e in errors:
        print(e, file=sys.stderr)
    print(f"{a.what}: {len(errors)} problem(s) in {len(pages(root))} pages")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
