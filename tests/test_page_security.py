"""The atlas page treats every outside value as text, and its Content-Security-Policy contains
what a slip would let through.

Outside values: the ``#open=`` part of the page's own address (anyone's to write: a link),
and what the store holds -- its title, model names, the labels and places of the series.
Each payload, if it ever ran, would set ``document.title`` to ``PWNED``; Chromium opens the
page and its DOM is read afterwards (``--dump-dom``): no payload ran, none of it became an
element, and it shows as text where the page shows it.  (A fragment put into
``innerHTML`` runs ``#open=<img src=x onerror=...>``'s script for whoever opens the link.)"""

import base64
import hashlib
import html
import os
import re
import urllib.parse
from html.parser import HTMLParser

import pytest

from spinviz.regimes.figures import draw
from spinviz.regimes.figures import page as PG

# every test here reads the refined atlas (~4 s of CPU to compute once): .ci/run's second pass
pytestmark = pytest.mark.slow


PAYLOAD = "document.title='PWNED'"
HOSTILE = [
    f"<img src=x onerror={PAYLOAD}>",                                        # runs if put into innerHTML
    f"<img src=x onerror=\"{PAYLOAD}\">",
    f"<svg onload={PAYLOAD}>",
    f"</title><script>{PAYLOAD}</script>",
    f"\"><img src=x onerror={PAYLOAD}>",
    f"javascript:{PAYLOAD}",
    f"</script><script>{PAYLOAD}</script><!--",
    f"\u202e\u03c9 \U0001f600 <img src=x onerror={PAYLOAD}>",
]
FRAGMENTS = HOSTILE + [
    "%3Cimg%20src%3Dx%20onerror%3D%22document.title%3D'PWNED'%22%3E",        # percent-encoded
    "A" * 20000 + f"<img src=x onerror={PAYLOAD}>",                           # very long
    "%E0%A4%A",                                                              # not decodable
    "__proto__",                                                             # an inherited key of the series
]


def chromium_or_skip():
    from browser import CHROMIUM

    if CHROMIUM is None:
        if os.environ.get("CI"):
            pytest.fail("CI must test the atlas page, but chromium is missing (see .ci/run)", pytrace=False)
        pytest.skip("needs chromium (apt-get install chromium)")


@pytest.fixture(scope="module")
def levels(refined_atlas):
    return draw.open_levels(str(refined_atlas.store))


def hostile_page(levels, value: str) -> tuple[str, str]:
    """(the page, a level-1 cell's id) of the atlas with the store's title, model name and the
    cell's series label and place all replaced by ``value``."""
    from spinviz.regimes.figures.cells import compose_levels

    bad = []
    for ds in levels:
        ds = ds.assign_coords(model=[value])
        ds.attrs["title"] = value
        bad.append(ds)
    cell = next(c for c in compose_levels(bad, value) if c["level"] == 1)
    fine = bad[1]
    omega = fine["series"].sel(model=value).isel(start=0).values[cell["i"], cell["j"]].astype(float)
    series = {cell["id"]: {"tau": fine["tau"].values, "omega": omega, "label": value,
                           "where": f"{value} model, \u03b4 = {cell['delta']:+.3f}"}}
    return PG.page(bad, series), cell["id"]


def no_payload_ran(dom: str, title: str) -> None:
    """The document's title is still ``title`` (every payload sets it to PWNED) and no element
    the payload would have made is in the DOM."""
    found = re.search(r"<title>(.*?)</title>", dom, re.S)
    assert found is not None and html.unescape(found.group(1)) == title, found
    made = Elements()
    made.feed(dom)
    # an element or handler the payload would have made (as text it is &lt;img ..., never markup)
    assert made.tags.isdisjoint({"img", "iframe", "object", "embed"}), made.tags
    assert made.handlers == [], made.handlers
    assert made.scripts == 2, made.scripts                     # the page's data block and its one script


class Elements(HTMLParser):
    """The element names, inline event handlers (attributes on...) and scripts of a document."""

    def __init__(self):
        super().__init__()
        self.tags, self.handlers, self.scripts = set(), [], 0

    def handle_starttag(self, tag, attrs):
        self.tags.add(tag)
        self.scripts += tag == "script"
        self.handlers += [(tag, name) for name, _ in attrs if name.lower().startswith("on")]


# --- fast: the markup itself --------------------------------------------------------------------
def test_the_page_carries_a_policy_that_allows_only_its_own_script_and_style(levels):
    text = PG.page_of(levels)
    meta = re.search(r'<meta http-equiv="Content-Security-Policy" content="([^"]+)">', text)
    assert meta is not None
    policy = html.unescape(meta.group(1))
    script = re.search(r"<script>(.*?)</script>", text, re.S).group(1)
    style = re.search(r"<style>(.*?)</style>", text, re.S).group(1)

    def sha(s):
        return "'sha256-" + base64.b64encode(hashlib.sha256(s.encode()).digest()).decode() + "'"

    assert policy == (f"default-src 'none'; script-src {sha(script)}; style-src {sha(style)}; base-uri 'none'; "
                      f"form-action 'none'")
    assert text.count("<script>") == 1                         # one script, the hashed one (and one JSON data block)
    assert not re.search(r"\son\w+=", text)                    # no inline event handler
    assert " style=" not in text                               # no style attribute (the policy would refuse it)
    assert "innerHTML" not in script and "insertAdjacentHTML" not in script and "document.write" not in script


@pytest.mark.parametrize("value", HOSTILE)
def test_store_values_are_escaped_in_the_markup(levels, value):
    text, _ = hostile_page(levels, value)
    body = re.sub(r"<script\b.*?</script>", "", text, flags=re.S)
    assert "<img" not in body and "<svg onload" not in body and "</title><script>" not in text.replace(
        "<title>", "", 1)
    data = re.search(r'<script type="application/json" id="series">(.*?)</script>', text, re.S).group(1)
    assert "<" not in data                                     # nothing in the data can end or change its block


# --- in Chromium ----------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("fragment", FRAGMENTS, ids=[f"fragment{i}" for i in range(len(FRAGMENTS))])
def test_a_hostile_fragment_runs_nothing(levels, tmp_path, fragment):
    from browser import page_text

    chromium_or_skip()
    page = tmp_path / "a.html"
    page.write_text(PG.page_of(levels), encoding="utf-8")
    dom, text = page_text(page, tmp_path, fragment=f"open={fragment}")
    no_payload_ran(dom, levels[0].attrs["title"])
    if fragment.startswith("<img"):                            # shown, as text, where the page says what it opened
        assert "<img src=x onerror" in text and ": no stored series for this cell" in text


@pytest.mark.slow
@pytest.mark.parametrize("csp", [True, False], ids=["with-policy", "without-policy"])
def test_hostile_store_values_run_nothing(levels, tmp_path, csp):
    """Titles, model names and labels from the store, opened at one of the hostile cells:
    nothing runs -- also with the policy taken out, so the escaping holds on its own."""
    from browser import page_text

    chromium_or_skip()
    value = HOSTILE[0]
    text, cid = hostile_page(levels, value)
    if not csp:
        text = re.sub(r'<meta http-equiv="Content-Security-Policy"[^>]*>', "", text)
        assert "Content-Security-Policy" not in text
    page = tmp_path / "h.html"
    page.write_text(text, encoding="utf-8")
    dom, shown = page_text(page, tmp_path, fragment="open=" + urllib.parse.quote(cid, safe=""))
    no_payload_ran(dom, value)
    assert f"{value} model, \u03b4 = " in shown and f"first start, label {value}" in shown   # as text


@pytest.mark.slow
def test_the_policy_contains_a_slip(levels, tmp_path):
    """A future escaping slip, simulated: an inline handler and an unhashed script put into the
    page.  The policy refuses both, while the page's own script still runs (the hodograph of
    the fragment's cell is drawn)."""
    from browser import page_text

    chromium_or_skip()
    text = PG.page_of(levels)
    slip = f"<img src=x onerror=\"{PAYLOAD}\"><script>{PAYLOAD}</script><div style=\"display:none\">x</div>"
    text = text.replace("<h1>", slip + "<h1>", 1)
    page = tmp_path / "slip.html"
    page.write_text(text, encoding="utf-8")
    cid = re.search(r'data-id="(reduced:1:\d+:\d+)"', text).group(1)
    dom, shown = page_text(page, tmp_path, fragment=f"open={cid}")
    assert html.unescape(re.search(r"<title>(.*?)</title>", dom, re.S).group(1)) == levels[0].attrs["title"]
    assert "first start, label" in shown                        # the page's own script ran under the policy
