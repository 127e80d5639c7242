"""What user-facing text must and must not say: shared by the source scan (``test_ui_text.py``) and the RNA walk
(``test_blender_ui_text.py``).

Papers, equations, thesis sections and our own research notes belong in ``docs/references.md``; the interface says
what a setting does in the artist's words.
"""

import re

#: Research jargon: citations of the source documents, equation and figure numbers, the papers' symbols and
#: abbreviations, author names. (A random "Seed" or "seed points" of a texture is plain language and allowed.)
JARGON = re.compile(
    r"\bthe seed\b(?! points)|\bseed'?s?\s+(?:0\d\d|eq|kernel|fig|§|table|behaviou?r|errat)|seed's\b"
    r"|\beqs?\.\s*\d|\bequation\s*\d|§|\bdigest\b|\berrat(?:um|a)\b|\bHAM\b|\bT_(?:max|min)\b|\bas printed\b"
    r"|\bfig\.\s*\d|\bet al\b|\bVlachos|\bBoubekeur|\bb_tran|\bb_tela\b|\bOL0\b|\(beta\)|\btable\s+\d\.\d"
    r"|[κεĥ]|\bthe thesis\b|\bthe paper\b|\bthe report's\b|\bMikkTSpace\b|\bHCE\b",
    re.IGNORECASE,
)

#: Text that reads like a menu path: ``Object › Tessera › Bake Impostor``, ``Add > Tessera > Terrain ...``.
MENU_PATH = re.compile(r"\b(Add|Object|File ?[›>] ?Export|View3D ?[›>] ?Sidebar|Sidebar)\s*[›>]\s*(Tessera)\s*[›>]\s*"
                       r"([A-Z][^*\n]*)")

#: The longest operator description (one sentence, shown in a tooltip).
MAX_DESCRIPTION = 160


def jargon(text):
    """The jargon found in ``text`` (a list of matches; empty when clean)."""
    return [m.group(0) for m in JARGON.finditer(text or "")]


def description_problems(text):
    """Why ``text`` is not a one-sentence operator description (a list; empty when it is one)."""
    problems = []
    if not text or not text.strip():
        problems.append("empty")
        return problems
    if "\n" in text:
        problems.append("hard line break")
    if len(text) > MAX_DESCRIPTION:
        problems.append(f"{len(text)} characters (at most {MAX_DESCRIPTION})")
    if re.search(r"[.!?;]\s+[A-Z]", text):
        problems.append("more than one sentence")
    return problems
