"""The size limits issue 27 set for the renderer's code: no file in native/render/ over 400
lines, and no function over 120 lines in native/render/ or shaders/. The functions are found
by their braces (comments, strings and preprocessor lines read past), so the scanner is
tested too, on code whose answer is known."""
import os
import re

import pytest

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
MAX_FILE_LINES = 400
MAX_FUNCTION_LINES = 120
SOURCES = (".cpp", ".h", ".glsl", ".comp")


def strip_comments_and_strings(text):
    """The text with comments, string and character literals blanked and preprocessor
    lines emptied, newlines kept so that line numbers hold."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" ")
            i = j + 1
        else:
            out.append(c)
            i += 1
    lines = "".join(out).split("\n")
    # A directive, with its continuation lines.
    keep, continued = [], False
    for line in lines:
        directive = continued or line.lstrip().startswith("#")
        continued = directive and line.rstrip().endswith("\\")
        keep.append("" if directive else line)
    return "\n".join(keep)


def functions(text):
    """(name, first line, line count) of every function body in C++ or GLSL text: a brace
    opened after a parameter list, directly in a namespace, a class or the file."""
    code = strip_comments_and_strings(text)
    found, stack, head, line = [], [], "", 1
    for c in code:
        if c == "\n":
            line += 1
        if c == "{":
            h = " ".join(head.split())
            in_function = any(kind == "function" for kind, _, _ in stack)
            if re.search(r"\bnamespace\b|\bextern\b", h) and "(" not in h:
                kind = "namespace"
            elif re.search(r"\b(struct|class|union|enum)\b", h) and "(" not in h:
                kind = "type"
            elif (not in_function and re.search(r"\)\s*(const|noexcept|override|final|"
                                                 r"->\s*[\w:<>, ]+|\s)*$", h)
                  and not re.search(r"=\s*[^=]*$", h.split("(")[0])):
                kind = "function"
            else:
                kind = "block"
            name = re.findall(r"([~\w:]+)\s*\(", h)
            stack.append((kind, line, name[0] if name else h[-40:]))
            head = ""
        elif c == "}":
            if stack:
                kind, first, name = stack.pop()
                if kind == "function":
                    found.append((name, first, line - first + 1))
            head = ""
        elif c == ";":
            head = ""
        else:
            head += c
    return found


def source_files(*folders):
    for folder in folders:
        for root, _, names in os.walk(os.path.join(REPO, folder)):
            for name in sorted(names):
                if name.endswith(SOURCES):
                    yield os.path.join(root, name)


def test_the_scanner_finds_functions_and_their_lengths():
    text = """// a comment with { braces }
namespace a {
struct S { int f() { return 1; } };
int g(int x) {
    const char* s = "}{";
    if (x) {
        return 2;
    }
#define OPEN {  \\
    {
    return 3;
}
}  // namespace a
void main() {
    uint k = 0u;
}
"""
    found = {name: (first, count) for name, first, count in functions(text)}
    assert found == {"f": (3, 1), "g": (4, 9), "main": (14, 3)}, found


def test_no_file_in_native_render_is_over_400_lines():
    long = []
    for path in source_files("native/render"):
        with open(path, encoding="utf-8") as f:
            count = sum(1 for _ in f)
        if count > MAX_FILE_LINES:
            long.append(f"{os.path.relpath(path, REPO)}: {count} lines")
    assert not long, long


@pytest.mark.parametrize("folder", ["native/render", "shaders"])
def test_no_function_is_over_120_lines(folder):
    long, seen = [], 0
    for path in source_files(folder):
        with open(path, encoding="utf-8") as f:
            for name, first, count in functions(f.read()):
                seen += 1
                if count > MAX_FUNCTION_LINES:
                    long.append(f"{os.path.relpath(path, REPO)}:{first} {name}: {count} lines")
    assert seen > 50, f"the scanner found only {seen} functions in {folder}"
    assert not long, long
