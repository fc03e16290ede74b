"""Tests of tools/bench/benchmarks_page.py: the block replacement, the sections' needs and
failures, the tables taken from a tool's output, and docs/benchmarks.md against the sections.

  python3 -m unittest tools.bench.test_benchmarks_page
"""

import io
import re
import sys
import tempfile
import unittest
from pathlib import Path

from tools.bench import benchmarks_page as bp

PAGE = ("# Page\r\n\nIntro with trailing spaces   \n\u00e9t\u00e9 \u2014 unicode\n\n"
        "<!-- bench:alpha begin -->\n_Measured 2026-11-26 at commit abc1234 on X (2 cores), 5 s:_"
        " `old`\n\n| a | b |\n| --- | --- |\n| 1 | 2 |\n<!-- bench:alpha end -->\n"
        "Between the blocks.\n<!-- bench:beta begin -->\n_Not measured yet._\n"
        "<!-- bench:beta end -->\nTail without a newline")


def section(sid, argv, needs=(), **kw):
    return bp.Section(sid, sid.title(), tuple(argv), tuple(needs), 1, **kw)


def printer(*lines):
    """A command that prints these lines (a stand-in for a bench tool)."""
    return (sys.executable, "-c", "import sys; print('\\n'.join(sys.argv[1:]))", *lines)


class BlockReplacement(unittest.TestCase):
    def test_outside_blocks_byte_for_byte(self):
        new = bp.replace_block(PAGE, "alpha", "_Measured new:_ `cmd`\n\n| x |\n|---|\n")
        begin = "<!-- bench:alpha begin -->\n"
        end = "<!-- bench:alpha end -->"
        head = PAGE[:PAGE.index(begin) + len(begin)]
        tail = PAGE[PAGE.index(end):]
        self.assertTrue(new.startswith(head))
        self.assertTrue(new.endswith(tail))
        self.assertEqual(new, head + "_Measured new:_ `cmd`\n\n| x |\n|---|\n" + tail)
        # the other block and the bytes around it are untouched
        self.assertEqual(bp.replace_block(new, "alpha", PAGE[len(head):PAGE.index(end)]), PAGE)

    def test_body_gets_a_final_newline(self):
        new = bp.replace_block(PAGE, "beta", "one line")
        self.assertIn("<!-- bench:beta begin -->\none line\n<!-- bench:beta end -->", new)

    def test_missing_block_names_the_id(self):
        with self.assertRaises(bp.BlockError) as e:
            bp.replace_block(PAGE, "gamma", "x\n")
        self.assertIn("gamma", str(e.exception))

    def test_broken_markers_name_the_id(self):
        for page in (PAGE.replace("<!-- bench:beta end -->", ""),
                     PAGE + "\n<!-- bench:beta begin -->\n<!-- bench:beta end -->\n"):
            with self.assertRaises(bp.BlockError) as e:
                bp.replace_block(page, "beta", "x\n")
            self.assertIn("beta", str(e.exception))
            self.assertTrue(bp.check_page(page, [section("alpha", ()), section("beta", ())]))

    def test_check_page(self):
        secs = [section("alpha", ()), section("beta", ())]
        self.assertEqual(bp.check_page(PAGE, secs), [])
        errs = bp.check_page(PAGE, secs[:1] + [section("gamma", ())])
        self.assertEqual(len(errs), 2)
        self.assertTrue(any("gamma" in e for e in errs) and any("beta" in e for e in errs))


class Extraction(unittest.TestCase):
    OUT = "\n".join([
        "- machine: 2 logical CPUs", "- spp 64, reference 1024 spp", "",
        "| case | relMSE |", "| --- | ---: |", "| a | 0.1 |", "progress line", "",
        "## cornell-dynamic, 160x120", "", "| config | s |", "|---|---|", "| x | 1 |", "",
        "Rows per device: 1/2, 3/4", "Not a caption", "| t |", "|---|", "",
        "- a, this build: relMSE power / bvh = 2.1", "images: /tmp/x"])

    def test_tables_and_captions(self):
        got = bp.extract(self.OUT, caption=r"^- spp ", keep=r"^Rows per device|relMSE \S+ / ")
        self.assertEqual(got, "\n".join([
            "- spp 64, reference 1024 spp", "", "| case | relMSE |", "| --- | ---: |",
            "| a | 0.1 |", "", "**cornell-dynamic, 160x120**", "", "| config | s |", "|---|---|",
            "| x | 1 |", "", "Rows per device: 1/2, 3/4", "", "| t |", "|---|", "",
            "- a, this build: relMSE power / bvh = 2.1"]) + "\n")

    def test_no_table(self):
        self.assertEqual(bp.extract("just text\n- list:\n"), "")

    def test_asset_lines_become_a_table(self):
        line = ("StainedGlassLamp   luminance 0.969  rgb 0.956 0.974 0.978  blocks p95 0.095 max "
                "0.310  pixels 0.0630 (120 blocks, 30000 px)")
        got = bp.asset_table("progress\n" + line + "\n")
        self.assertIn("| StainedGlassLamp | 0.969 | 0.956 0.974 0.978 | 0.095 | 0.310 | 0.0630 "
                      "| 120 | 30000 |  |", got)
        parts = line + "  parts worst 0.912 (RubberWoodMat) of 6"
        self.assertIn("| 30000 | 0.912 RubberWoodMat (of 6) |", bp.asset_table(parts + "\n"))
        self.assertEqual(bp.asset_table("nothing\n"), "")


class Regenerate(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.page = Path(self.dir.name) / "page.md"
        self.page.write_bytes(PAGE.encode())
        self.log = io.StringIO()

    def tearDown(self):
        self.dir.cleanup()

    def run_sections(self, secs, ctx=None):
        return bp.regenerate(secs, ctx or bp.Context("build"), self.page, log=self.log)

    def test_missing_needs_leave_the_block(self):
        secs = [section("alpha", printer("| new |", "|---|"), needs=("cycles",)),
                section("beta", printer("| new |", "|---|"), needs=("luxcore",))]
        self.assertEqual(self.run_sections(secs, bp.Context("build", cycles=None)), 0)
        self.assertEqual(self.page.read_bytes(), PAGE.encode())
        self.assertRegex(self.log.getvalue(), r"alpha: skipped, missing cycles \(--cycles PY")
        self.assertRegex(self.log.getvalue(), r"beta: skipped, missing luxcore")

    def test_a_section_replaces_its_block_only(self):
        secs = [section("beta", printer("noise", "## scene", "", "| new | t |", "|---|---|",
                                        "| 1 | 2 |", "done"))]
        self.assertEqual(self.run_sections(secs), 0)
        text = self.page.read_bytes().decode()
        body = text[text.index("<!-- bench:beta begin -->\n") + 26:
                    text.index("<!-- bench:beta end -->")]
        self.assertRegex(body.splitlines()[0], r"^_Measured \d{4}-\d\d-\d\d at commit \S+ on "
                         r".+ \(\d+ cores\), \d+ s:_ `.+`$")
        self.assertEqual(body.split("\n", 1)[1],
                         "\n**scene**\n\n| new | t |\n|---|---|\n| 1 | 2 |\n\n")
        self.assertEqual(bp.replace_block(text, "beta", "_Not measured yet._\n"), PAGE)

    def test_a_failure_leaves_its_block_and_the_others_run(self):
        fail = (sys.executable, "-c", "print('| partial |'); raise SystemExit(3)")
        secs = [section("alpha", fail), section("beta", printer("| ok |", "|---|"))]
        self.assertEqual(self.run_sections(secs), 1)
        text = self.page.read_text()
        self.assertIn("| a | b |\n| --- | --- |\n| 1 | 2 |\n<!-- bench:alpha end -->", text)
        self.assertIn("| ok |\n|---|\n\n<!-- bench:beta end -->", text)
        self.assertIn("alpha: FAILED (exit status 3)", self.log.getvalue())
        self.assertIn("1 failed", self.log.getvalue())

    def test_no_table_is_a_failure(self):
        self.assertEqual(self.run_sections([section("alpha", printer("no table here"))]), 1)
        self.assertEqual(self.page.read_bytes(), PAGE.encode())

    def test_a_missing_block_stops_before_running(self):
        marker = Path(self.dir.name) / "ran"
        secs = [section("alpha", (sys.executable, "-c", f"open({str(marker)!r}, 'w')")),
                section("gamma", printer("| x |"))]
        with self.assertRaises(bp.BlockError) as e:
            self.run_sections(secs)
        self.assertIn("gamma", str(e.exception))
        self.assertFalse(marker.exists())
        self.assertEqual(self.page.read_bytes(), PAGE.encode())


class RealPage(unittest.TestCase):
    """docs/benchmarks.md has exactly the sections' blocks, each starting with a date line."""

    def test_blocks_match_the_sections(self):
        text = bp.PAGE.read_text(encoding="utf-8")
        self.assertEqual(bp.check_page(text, bp.SECTIONS), [])
        self.assertEqual(len({s.id for s in bp.SECTIONS}), len(bp.SECTIONS))

    def test_each_block_starts_with_its_measured_line(self):
        text = bp.PAGE.read_text(encoding="utf-8")
        for sid in bp.block_ids(text):
            body = text.split(f"<!-- bench:{sid} begin -->\n", 1)[1]
            first = body.split("\n", 1)[0]
            self.assertRegex(first, r"^_(Measured .*:_ `.+`|Not measured by this command yet.*_)$",
                             sid)

    def test_each_section_has_its_heading(self):
        text = bp.PAGE.read_text(encoding="utf-8")
        for s in bp.SECTIONS:
            title = s.title[0].lower() + s.title[1:]
            self.assertIn(f"\n### `{s.id}`: {title}\n", text, s.id)

    def test_sections_are_well_formed(self):
        for s in bp.SECTIONS:
            self.assertTrue(re.fullmatch(r"[a-z0-9-]+", s.id), s.id)
            self.assertTrue(set(s.needs) <= set(bp.NEEDS), s.id)
            filled = bp.Context("build", "C", "L").fill(s.argv)
            self.assertFalse(any("{" in a for a in filled), s.id)
            for w in s.writes[:1]:
                self.assertTrue((bp.REPO / w).is_file(), w)


if __name__ == "__main__":
    unittest.main()
