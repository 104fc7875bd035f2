#!/usr/bin/env python3
"""Purpose: every YAML snippet in the docs is run through `trackflow validate` (issue 26: docs that are tested).

Each ```yaml fence in README.md, docs/*.md and examples/*/README.md must be preceded (on the line
before the fence, blank lines allowed) by one marker comment saying how it is checked:

  <!-- checked: whole pipeline -->
      the snippet is a pipeline file: validated, then run with --runs 2 (exit 0, or 1 for a failed
      expect check; exit 2 - an unknown metric, say - fails the test)
  <!-- checked: nodes in pipelines/X.yaml -->
      the snippet is a list of nodes: each replaces the node of the same id in X, or is appended
      to X's nodes; the result is validated
  <!-- checked: params of node N in pipelines/X.yaml -->
      the snippet is a mapping of parameters: each key is given to node N of X as --set N.key=...
      and the result is validated

A fence without a marker, a marker naming a file or node that does not exist, and a snippet that
does not validate all fail. With --corrupt, every snippet's first `type:` value is misspelled and
every snippet must then FAIL: the check proves it can fail.

Usage: docs_snippets.py TRACKFLOW PLUGIN_DIR REPO_ROOT [--corrupt]
"""
import glob
import os
import re
import subprocess
import sys
import tempfile

import yaml

MARKER = re.compile(r"<!--\s*checked:\s*(.*?)\s*-->")
NODES_IN = re.compile(r"^nodes in (\S+\.yaml)$")
PARAMS_OF = re.compile(r"^params of node (\S+) in (\S+\.yaml)$")


def snippets(root):
    """Yields (file, line, marker text or None, snippet text) for every ```yaml fence."""
    files = [os.path.join(root, "README.md")]
    files += sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    files += sorted(glob.glob(os.path.join(root, "examples", "*", "README.md")))
    for path in files:
        lines = open(path, encoding="utf-8").read().split("\n")
        i = 0
        while i < len(lines):
            if lines[i].strip() in ("```yaml", "```yml"):
                start = i
                j = i - 1
                while j >= 0 and not lines[j].strip():
                    j -= 1
                m = MARKER.search(lines[j]) if j >= 0 else None
                k = i + 1
                while k < len(lines) and lines[k].strip() != "```":
                    k += 1
                if k == len(lines):
                    raise SystemExit(f"{path}:{start + 1}: a ```yaml fence that is never closed")
                yield path, start + 1, (m.group(1) if m else None), "\n".join(lines[i + 1:k]) + "\n"
                i = k
            i += 1


def corrupt(text):
    """Misspells the first `type:` value: a snippet whose check cannot fail is no check."""
    out, n = re.subn(r"(type:\s*)([A-Za-z_.]+)", r"\1\2_misspelt", text, count=1)
    if n == 0:
        raise ValueError("the snippet has no `type:` to misspell")
    return out


def item_text(text, node):
    """The source text of a composed YAML node, its continuation lines re-based to column 0."""
    body = text[node.start_mark.index:node.end_mark.index].rstrip()
    col = node.start_mark.column
    lines = body.split("\n")
    rest = [ln[col:] if ln[:col].strip() == "" else ln for ln in lines[1:]]
    return [lines[0]] + rest


def splice_nodes(host_text, snippet_text):
    """The host pipeline with each snippet node replacing its namesake or appended."""
    host = yaml.compose(host_text)
    seq = next((v for k, v in host.value if k.value == "nodes"), None)
    if seq is None or not isinstance(seq, yaml.SequenceNode) or seq.flow_style:
        raise ValueError("the host pipeline has no block list of nodes")
    snip = yaml.compose(snippet_text)
    if not isinstance(snip, yaml.SequenceNode):
        raise ValueError("a 'nodes in' snippet must be a list of nodes")

    def node_id(item):
        return next((v.value for k, v in item.value if k.value == "id"), None)

    edits = []  # (start, end, replacement text), applied from the back
    item_col = seq.value[0].start_mark.column
    last_end = seq.value[-1].end_mark.index
    appended = []
    for item in snip.value:
        lines = item_text(snippet_text, item)
        target = next((h for h in seq.value if node_id(h) == node_id(item)), None)
        indent = " " * item_col
        if target is not None:
            text = ("\n" + indent).join(lines)
            end = target.end_mark.index
            # A block mapping ends at the next token: keep the host's line breaks after it.
            while end > target.start_mark.index and host_text[end - 1] in " \n":
                end -= 1
            edits.append((target.start_mark.index, end, text))
        else:
            appended.append(" " * (item_col - 2) + "- " + ("\n" + indent).join(lines))
    end = last_end
    while host_text[end - 1] in " \n":
        end -= 1
    if appended:
        edits.append((end, end, "\n" + "\n".join(appended)))
    out = host_text
    for start, stop, text in sorted(edits, reverse=True):
        out = out[:start] + text + out[stop:]
    return out


def params_sets(node_id, snippet_text):
    """--set arguments giving each top-level key of a params snippet to the node."""
    snip = yaml.compose(snippet_text)
    if not isinstance(snip, yaml.MappingNode):
        raise ValueError("a 'params of node' snippet must be a mapping of parameters")
    args = []
    for key, value in snip.value:
        text = snippet_text[value.start_mark.index:value.end_mark.index].rstrip()
        if value.start_mark.line != key.start_mark.line:  # a block value: keep its first indent
            text = " " * value.start_mark.column + text
        args += ["--set", f"{node_id}.{key.value}={text}"]
    return args


def run(cmd, cwd):
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=300)
    return p.returncode, (p.stdout + p.stderr).strip()


def check(tf, plugins, root, path, line, marker, text, tmp, index):
    """None if the snippet validates, else the reason it does not."""
    base = [tf]
    plug = ["--no-default-plugins", "--plugin-path", plugins]
    if marker == "whole pipeline":
        f = os.path.join(tmp, f"snippet{index}.yaml")
        open(f, "w", encoding="utf-8").write(text)
        rc, out = run(base + ["validate", f] + plug, tmp)
        if rc != 0:
            return f"validate exit {rc}: {out}"
        rc, out = run(base + ["run", f, "--runs", "2", "--threads", "1", "--quiet",
                              "--out", os.path.join(tmp, f"out{index}")] + plug, tmp)
        if rc not in (0, 1):
            return f"run --runs 2 exit {rc}: {out}"
        return None
    m = NODES_IN.match(marker)
    if m:
        host = os.path.join(root, m.group(1))
        if not os.path.isfile(host):
            return f"the marker names {m.group(1)}, which does not exist"
        merged = splice_nodes(open(host, encoding="utf-8").read(), text)
        f = os.path.join(tmp, f"snippet{index}.yaml")
        open(f, "w", encoding="utf-8").write(merged)
        rc, out = run(base + ["validate", f] + plug, tmp)
        return None if rc == 0 else f"validate (in {m.group(1)}) exit {rc}: {out}"
    m = PARAMS_OF.match(marker)
    if m:
        host = os.path.join(root, m.group(2))
        if not os.path.isfile(host):
            return f"the marker names {m.group(2)}, which does not exist"
        rc, out = run(base + ["validate", host] + params_sets(m.group(1), text) + plug, tmp)
        return None if rc == 0 else f"validate (node {m.group(1)} of {m.group(2)}) exit {rc}: {out}"
    return f"unknown marker 'checked: {marker}' (see tests/support/docs_snippets.py)"


def main():
    if len(sys.argv) not in (4, 5) or (len(sys.argv) == 5 and sys.argv[4] != "--corrupt"):
        raise SystemExit(__doc__)
    tf, plugins, root = (os.path.abspath(a) for a in sys.argv[1:4])
    corrupting = len(sys.argv) == 5
    failures, count = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for index, (path, line, marker, text) in enumerate(snippets(root)):
            count += 1
            where = f"{os.path.relpath(path, root)}:{line}"
            if marker is None:
                failures.append(f"{where}: a ```yaml fence without a '<!-- checked: ... -->' marker")
                continue
            try:
                reason = check(tf, plugins, root, path, line, marker,
                               corrupt(text) if corrupting else text, tmp, index)
            except (ValueError, yaml.YAMLError) as e:
                reason = f"cannot be checked: {e}"
            if corrupting:
                if reason is None:
                    failures.append(f"{where}: still validates with a misspelt type: the check cannot fail")
                else:
                    print(f"ok: {where} fails when corrupted")
            elif reason is None:
                print(f"ok: {where} ({marker})")
            else:
                failures.append(f"{where} ({marker}): {reason}")
    for f in failures:
        print("FAIL: " + f, file=sys.stderr)
    if count == 0:
        print("FAIL: no ```yaml snippet found: the check ran nothing", file=sys.stderr)
        return 1
    print(f"{count - len(failures)} of {count} snippets {'fail when corrupted' if corrupting else 'validate'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
