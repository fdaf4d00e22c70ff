"""Tables as the terminal shows them and as docs/benchmark.md holds them."""
import dataclasses
import math
import re
from typing import List


def fmt(value, digits=3):
    """A figure with `digits` decimals; "-" for a missing one (None or NaN)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    return "{:.{}f}".format(value, digits)


def arrow(before, after, digits=3):
    """"before -> after"."""
    return "{} -> {}".format(fmt(before, digits), fmt(after, digits))


@dataclasses.dataclass
class Table:
    """One printed table: a title, the column names and rows of cells (any str()-able);
    `docs`: it also goes into docs/benchmark.md."""
    title: str
    header: List[str]
    rows: List[list]
    docs: bool = True


@dataclasses.dataclass
class Line:
    """A line a table module prints instead of or beside its tables (`docs`: it also goes
    into docs/benchmark.md)."""
    text: str
    docs: bool = True


def text(table):
    """The table (or Line) as the terminal shows it: a blank line, the title, aligned
    columns."""
    if isinstance(table, Line):
        return "\n" + table.text
    cells = [[str(c) for c in row] for row in table.rows]
    widths = [max([len(str(h))] + [len(r[i]) for r in cells]) for i, h in enumerate(table.header)]
    lines = ["", table.title, " | ".join(str(h).ljust(w) for h, w in zip(table.header, widths)),
             "-+-".join("-" * w for w in widths)]
    lines += [" | ".join(c.ljust(w) for c, w in zip(r, widths)) for r in cells]
    return "\n".join(lines)


def markdown(table):
    """The table as a Markdown table under a bold title (a Line as a paragraph)."""
    if isinstance(table, Line):
        return table.text
    def row(cells):
        return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"
    lines = ["**%s**" % table.title, "", row(table.header), "|" + "---|" * len(table.header)]
    lines += [row(r) for r in table.rows]
    return "\n".join(lines)


def begin_marker(name):
    return "<!-- irm_bench:begin %s -->" % name


def end_marker(name):
    return "<!-- irm_bench:end %s -->" % name


def replace_section(document, name, body):
    """`document` with the text between the section's markers replaced by `body`; the
    section is appended (markers included) when the document has none."""
    begin, end = begin_marker(name), end_marker(name)
    pattern = re.compile(re.escape(begin) + r"\n.*?" + re.escape(end), re.S)
    section = "%s\n%s\n%s" % (begin, body.strip("\n"), end)
    if pattern.search(document):
        return pattern.sub(lambda _: section, document, count=1)
    return document.rstrip("\n") + "\n\n" + section + "\n"
