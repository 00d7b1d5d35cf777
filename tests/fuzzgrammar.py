"""Random programs expanded from the language's grammar, lang/lig.lark.

The grammar is read with Lark's own loader (``lark.load_grammar``), which
gives plain BNF rules and the terminals with their patterns. Expansion is
random but steered so that a good share of the programs parse, pass the
checker and run:

* the choice between a rule's expansions is weighted by the *kind* of
  value the context wants (a vector after TRANS, a motion after USING, a
  graphical object in BACKGROUND...) and by where it is (ANIMATE inside a
  scene, DRAW inside a PRIMITIVE, LOAD at the top level);
* names come from pools of each kind (most programs start with a prelude
  that declares and assigns them), numbers from a list of sensible ones,
  keywords are spelled from their terminals' patterns (in mixed case now
  and then);
* scene lengths, loop bounds and keyframe indices are small literals, so
  that every case runs in a fraction of a second;
* past a depth limit the cheapest expansion is taken, so expansion ends.

The expansion never leaves the grammar: every program is a sentence of
lig.lark, except that a DO gets its CONTINUE and that a primitive call
inside a comma list is put in parentheses (the LALR parser would otherwise
give the list's commas to the call, as it does for users).
"""

from __future__ import annotations

import functools
import os
import re
import re._parser as _sre  # the stdlib's regex parser, to sample strings from terminal patterns
from collections import defaultdict
from importlib import resources

from lark.load_grammar import load_grammar

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: Value kinds an expansion aims at (the checker's types, roughly).
NUM, INT, VEC, PAIR, GRAPH, MODEL, MOTION, COND = "N", "I", "V", "P", "G", "M", "W", "C"

#: The prelude's names, by kind.
PRELUDE_NAMES = {
    INT: ["I", "J", "K"],
    NUM: ["A", "B"],
    VEC: ["V1", "V2"],
    GRAPH: ["G1", "G2", "G3"],
    MODEL: ["M1", "M2"],
    MOTION: ["W1", "W2"],
}
DECLARATIONS = """\
      INTEGER I, J, K
      REAL A, B
      VECTOR V1, V2
      GRAPHICAL G1, G2, G3
      MODEL M1, M2
      MOTION W1, W2
"""
VALUES = """\
      I = 1
      J = 2
      K = 3
      A = 0.5
      B = 2.0
      V1 = (0.0, 1.0, 0.0)
      V2 = (1.0, 0.0, 0.0)
      G1 :- BOX WIDTH 1.0, HEIGHT 0.5, DEPTH 0.5
      G2 :- BOX AT (0.0, 0.5, 0.0), WIDTH 0.2, HEIGHT 1.0, DEPTH 0.2
      G3 :- BOX WIDTH 0.3, HEIGHT 0.3, DEPTH 0.3, LIGHTNESS 40.0
      M1 :- JOINT 1, G1, (0.0, 0.25, 0.0), G2, (0.0, 0.0, 0.0), (0°, 0°), (0°, 0°), (-90°, 90°)
      M2 :- JOINT 2, M1, (0.0, 1.0, 0.0), G3, (0.0, 0.0, 0.0), (-45°, 45°), (0°, 0°), (0°, 0°)
      W1[1, 1] = FRAME 0 POSITION (0.0, 0.0, 0.0)
      W1[1, 2] = FRAME 2 POSITION (0.0, 0.0, 45.0)
      W2 = W1 <SCALE FRAMES 2>
"""

# The built-in functions (compiler/types.py), as argument kinds and result kind.
_FUNCTIONS = {
    "SIN": ([NUM], NUM),
    "COS": ([NUM], NUM),
    "TAN": ([NUM], NUM),
    "ASIN": ([NUM], NUM),
    "ACOS": ([NUM], NUM),
    "ATAN": ([NUM], NUM),
    "ATAN2": ([NUM, NUM], NUM),
    "SQRT": ([NUM], NUM),
    "EXP": ([NUM], NUM),
    "LOG": ([NUM], NUM),
    "ABS": ([NUM], NUM),
    "INT": ([NUM], NUM),
    "NINT": ([NUM], NUM),
    "REAL": ([NUM], NUM),
    "FLOAT": ([NUM], NUM),
    "MIN": ([NUM, NUM], NUM),
    "MAX": ([NUM, NUM], NUM),
    "MOD": ([NUM, NUM], NUM),
    "DOT": ([VEC, VEC], NUM),
    "CROSS": ([VEC, VEC], VEC),
    "NORM": ([VEC], NUM),
    "X": ([VEC], NUM),
    "Y": ([VEC], NUM),
    "Z": ([VEC], NUM),
    "LEN": ([MOTION], NUM),
}
_NUMBERS = [
    "0",
    "1",
    "2",
    "3",
    "0.5",
    "1.5",
    "2.5",
    "10",
    "45",
    "90",
    "180",
    "360",
    "0.25",
    ".5",
    "7",
    "135°",
    "30°",
    "1e3",
    "0.0",
    "1.0",
]
_ODD_NUMBERS = ["1e6", "99999", "1e308", "1e-5", "0.000001", "123456789", "1e30", "4e2°"]
_EDGE_NUMBERS = ["1e309", "5e-324", "9223372036854775808", "1" + "0" * 400, "1e12", "1e9", "0.0000", "0e0"]
_SMALL = ["0", "1", "2", "1", "2", "3"]
_INTERPOLATIONS = ["LINEAR", "ACCDCC", "ACCELERATE", "DECELERATE", "LINEAR", "BOUNCE"]
_SOLVERS = ["DLS", "TRANSPOSE", "CCD", "NEWTON"]
#: BOX's clauses as (word, kind, optional), in order.
_BOX = [
    ("AT", VEC, True),
    ("WIDTH", NUM, False),
    ("HEIGHT", NUM, False),
    ("DEPTH", NUM, False),
    ("LIGHTNESS", NUM, True),
]
_PRIMITIVE_HEADS = ["PEG", "SLAB"]
_PARAMS = ["CENTRE", "S", "W", "LIGHT"]
_LINE_STARTS = ("statement", "top", "joint_stmt", "motion_joint", "keyframe", "reach_item", "_prim_item")
_NESTING = ("if_stmt", "block", "scene_block", "model_block", "motion_block", "primitive_def", "reach_block")
_BLOCKS = ("if_stmt", "model_block", "motion_block", "scene_block", "reach_block", "do_stmt")
_STATEMENT_WEIGHTS = {
    "declaration": 1.0,
    "assignment": 9.0,
    "keyframe_assign": 2.0,
    "do_stmt": 1.0,
    "continue_stmt": 0.02,
    "if_stmt": 1.2,
    "model_block": 0.8,
    "motion_block": 0.8,
    "figure_stmt": 0.5,
    "scene_block": 1.5,
    "animate_stmt": 0.05,
    "background_stmt": 0.1,
    "print_stmt": 1.5,
    "view_stmt": 0.1,
    "shoot_stmt": 0.8,
    "stop_stmt": 0.1,
    "return_stmt": 0.02,
    "draw_with": 0.02,
    "draw_poly": 0.02,
    "load_stmt": 0.5,
    "reach_block": 0.5,
}
_MODIFIER_WEIGHTS = {
    GRAPH: {"mod_trans": 3, "mod_rot": 3, "mod_scale": 2, "mod_lightness": 2},
    MODEL: {
        "mod_trans": 3,
        "mod_rot": 2,
        "mod_scale_model": 2,
        "mod_scale_extremes": 1,
        "mod_scale": 1,
        "mod_trans_joints": 1,
        "mod_lightness": 0.1,
    },
    MOTION: {"mod_scale_frames": 3, "mod_scale_extremes": 2},
}


@functools.lru_cache(maxsize=1)
def stdlib_exports() -> dict:
    """``{library: {name: kind or clause list}}``: what each standard library declares.

    MODELs and MOTIONs map to their kind; PRIMITIVEs to their clauses
    ``[(word, kind, optional), ...]`` read from the invocation pattern.
    """
    out = {}
    folder = os.path.join(ROOT, "stdlib")
    for file in sorted(os.listdir(folder)):
        if not file.endswith(".lig"):
            continue
        with open(os.path.join(folder, file), encoding="utf-8") as fh:
            text = fh.read()
        names: dict = {}
        for kind, word in ((MODEL, "MODEL"), (MOTION, "MOTION")):
            for m in re.finditer(rf"(?im)^[ \t]+{word}[ \t]+([A-Z0-9_, \t]+)$", text):
                names.update((n.strip().upper(), kind) for n in m.group(1).split(",") if n.strip())
        for m in re.finditer(r"(?ims)^[ \t]+([A-Z][A-Z0-9_]*)[ \t]*::=(.*?);", text):
            names[m.group(1).upper()] = _clauses_of(m.group(2))
        out[file[:-4]] = names
    return out


def _clauses_of(pattern: str) -> list:
    """The clause words of an invocation pattern, with their kinds and whether they are optional."""
    pattern = re.sub(r"<[^>]*>", " ", pattern)
    clauses, depth, first = [], 0, True
    for tok in re.findall(r"\[|\]|'[^']*'", pattern):
        if tok == "[":
            depth += 1
        elif tok == "]":
            depth -= 1
        elif tok != "','":
            if first:  # the primitive's own name
                first = False
                continue
            word = tok.strip("'").upper()
            kind = VEC if word == "AT" else (INT if word in ("SIDES", "BANDS") else NUM)
            clauses.append((word, kind, depth > 0))
    return clauses


class Grammar:
    """lig.lark as BNF: rules by name, terminals by name, the cheapest derivation of each rule.

    Lark's compiled rules are plain BNF: EBNF repetitions become
    left-recursive rules named ``__<rule>_star_<n>`` or ``_plus_``, and
    optional parts become separate expansions.
    """

    def __init__(self, text: str):
        grammar, _ = load_grammar(text, "lig.lark", None, False)
        terminals, rules, _ = grammar.compile(["start"], set())
        self.terminals = {t.name: t for t in terminals}
        self.rules: dict = defaultdict(list)
        for r in rules:
            self.rules[r.origin.name].append(r)
        self.cost = self._min_costs()

    def _min_costs(self) -> dict:
        """The fewest tokens each rule can produce (a fixpoint)."""
        cost = {name: float("inf") for name in self.rules}
        changed = True
        while changed:
            changed = False
            for name, rules in self.rules.items():
                best = min(self.expansion_cost(r, cost) for r in rules)
                if best < cost[name]:
                    cost[name] = best
                    changed = True
        return cost

    def expansion_cost(self, rule, cost=None) -> float:
        """Tokens the cheapest derivation of one expansion produces."""
        cost = cost if cost is not None else self.cost
        return sum(1 if s.is_term else cost[s.name] for s in rule.expansion)

    @staticmethod
    def is_repetition(name: str) -> bool:
        """Is this one of Lark's left-recursive rules for ``x*`` or ``x+``?"""
        return name.startswith("__") and ("_star_" in name or "_plus_" in name)

    def is_terminal(self, name: str) -> bool:
        """A terminal, or PRIM_NAME (declared, made by the post-lexer)."""
        return name in self.terminals or name == "PRIM_NAME"


@functools.lru_cache(maxsize=1)
def grammar() -> Grammar:
    """The language's grammar, read once."""
    return Grammar(resources.files("liganimate.lang").joinpath("lig.lark").read_text(encoding="utf-8"))


def sample_regex(pattern: str, rng) -> str:
    """A string matching ``pattern``: the regex subset the grammar's keyword terminals use.

    Anchors, word boundaries and lookaheads produce nothing; repeats are short.
    """
    return _sample(_sre.parse(pattern), rng)


def _sample(items, rng) -> str:
    out = []
    for op, arg in items:
        op = str(op)
        if op == "LITERAL":
            out.append(chr(arg))
        elif op == "IN":
            out.append(_sample_class(arg, rng))
        elif op == "BRANCH":
            out.append(_sample(rng.choice(arg[1]), rng))
        elif op == "SUBPATTERN":
            out.append(_sample(arg[3], rng))
        elif op in ("MAX_REPEAT", "MIN_REPEAT", "POSSESSIVE_REPEAT"):
            lo, hi, sub = arg
            n = lo + rng.randrange(min(hi, lo + 2) - lo + 1)
            out.extend(_sample(sub, rng) for _ in range(n))
        elif op == "ANY":
            out.append("a")
        elif op == "CATEGORY":
            out.append({"CATEGORY_DIGIT": "7", "CATEGORY_SPACE": " "}.get(str(arg), "a"))
    return "".join(out)


def _sample_class(items, rng) -> str:
    choices = []
    for op, arg in items:
        op = str(op)
        if op == "LITERAL":
            choices.append(chr(arg))
        elif op == "RANGE":
            choices.append(chr(arg[0] + rng.randrange(arg[1] - arg[0] + 1)))
        elif op == "CATEGORY":
            choices.append({"CATEGORY_DIGIT": "3", "CATEGORY_SPACE": " "}.get(str(arg), "q"))
    return rng.choice(choices) if choices else "a"


class Expander:
    """Expands the grammar at random into one program's tokens (see the module's docstring)."""

    MAX_DEPTH = 32

    def __init__(self, rng, names: dict, wild: tuple = (), wild_rate: float = 0.0):
        self.rng = rng
        self.wild, self.wild_rate = wild, wild_rate  # extra numbers, and how often one is taken
        self.g = grammar()
        self.exports = stdlib_exports()
        self.names = {k: list(v) for k, v in names.items()}
        self.tokens: list = []  # strings, and None where a statement starts (a line break)
        self.labels: list = []  # DO labels still open
        self.next_label = 10
        self.prims = {"BOX": _BOX}  # primitive name -> clauses [(word, kind, optional)]
        self.prim_now: str | None = None  # the PRIMITIVE being defined
        self.prim_pattern = False  # has it an invocation pattern yet?
        self.pattern_items = 0  # items of the pattern being written
        self.in_scene = self.nesting = self.in_model = 0
        self.library = "shapes"  # the library of the LOAD being written
        self.plan: list = []  # the clauses still to write in the primitive call being written
        self.commas = 0  # comma lists open around the current expansion
        self.case_flips = rng.random() < 0.3  # write some keywords in mixed case

    # ------------------------------------------------------------ choices
    def pick(self, weighted):
        """One item of ``[(weight, item), ...]``."""
        total = sum(w for w, _ in weighted)
        x = self.rng.random() * total
        for w, item in weighted:
            x -= w
            if x < 0:
                return item
        return weighted[-1][1]

    def name_of(self, kind) -> str:
        """A name of that kind (now and then any name)."""
        pool = self.names.get(kind) or []
        if kind is None or not pool or self.rng.random() < 0.02:
            pool = [n for names in self.names.values() for n in names]
        return self.rng.choice(pool)

    def kind_of(self, name: str):
        """The kind of a pooled name, or None for a name the pools do not know."""
        for kind, names in self.names.items():
            if name in names:
                return kind
        return None

    def offer(self, name: str, what) -> None:
        """A LOAD brings ``name`` (a kind, or a primitive's clauses): later statements may use it."""
        if isinstance(what, list):
            self.prims[name] = what
        elif what and name not in self.names.setdefault(what, []):
            self.names[what].append(name)

    def number(self, kind) -> str:
        """A NUMBER token: small for INT slots, else mostly sensible, now and then odd or extreme."""
        if kind == INT:
            return self.rng.choice(_SMALL)
        if self.wild and self.rng.random() < self.wild_rate:
            return self.rng.choice(self.wild)
        r = self.rng.random()
        if r < 0.05:
            return self.rng.choice(_ODD_NUMBERS if r < 0.04 else _EDGE_NUMBERS)
        return self.rng.choice(_NUMBERS)

    def cased(self, word: str) -> str:
        """``word``, in mixed case now and then (keywords are case-insensitive)."""
        if self.case_flips and self.rng.random() < 0.3:
            return "".join(c.lower() if self.rng.random() < 0.5 else c for c in word)
        return word

    # ------------------------------------------------------------ expansion
    def expand(self, name: str, depth: int, kind=None) -> None:
        """Append the tokens of one random derivation of rule ``name``."""
        g = self.g
        if g.is_terminal(name):
            self.tokens.append(self.terminal(name, kind, {}))
            return
        if name == "expr" and kind == INT:
            # Scene lengths, loop bounds, keyframe indices: small literals keep cases fast.
            self.tokens.append(self.rng.choice(_SMALL))
            return
        if g.is_repetition(name):
            self.repeat(name, depth, kind)
            return
        rules = g.rules[name]
        if depth >= self.MAX_DEPTH:
            best = min(g.expansion_cost(r) for r in rules)
            rule = self.pick([(self.weight(name, r, kind, depth), r) for r in rules if g.expansion_cost(r) == best])
        else:
            rule = self.pick([(self.weight(name, r, kind, depth), r) for r in rules])
        self.derive(name, rule, depth, kind)

    def derive(self, name: str, rule, depth: int, kind) -> None:
        """Append the tokens of expansion ``rule`` of ``name``."""
        symbols = [s.name for s in rule.expansion]
        if name in _LINE_STARTS:
            self.tokens.append(None)
        local: dict = {"alias": rule.alias}
        saved = (self.library, self.plan, self.commas, self.prim_now, self.in_scene, self.nesting, self.in_model)
        # A primitive call with clauses takes every ", NAME expr" after it, so
        # inside a comma list it must be in parentheses to parse as meant.
        wrap = name == "prim_call" and len(symbols) > 1 and self.commas > 0
        if wrap:
            self.tokens.append("(")
        if name == "statement" or (name in ("atom", "catom") and symbols[0] == "LPAR" and rule.alias is None):
            self.commas = 0
        elif "COMMA" in symbols or any(s.startswith("__") and s != "__start_star_0" for s in symbols):
            self.commas += 1
        if name == "load_stmt":
            self.library = self.rng.choice(sorted(self.exports))
        self.in_scene += name == "scene_block"
        self.in_model += name == "model_block"
        self.nesting += name in _NESTING
        if name in ("primitive_def", "pattern_def"):
            self.prim_pattern = name == "pattern_def"
            self.pattern_items = 0
        for i, sym in enumerate(symbols):
            child = self.child_kind(name, rule, symbols, i, kind, local)
            if self.g.is_terminal(sym):
                self.tokens.append(self.terminal(sym, child, local, name, symbols, i))
            else:
                self.expand(sym, depth + 1, child)
        if name == "do_stmt" and self.rng.random() < 0.85:
            self.nesting += 1
            self.labels.remove(local["label"])  # the body's statements must not close it
            for _ in range(1 + self.rng.randrange(2)):
                self.expand("statement", depth + 1)
            self.tokens += [None, local["label"], "CONTINUE"]
        if name == "load_stmt" and len(symbols) == 2:
            for n, what in self.exports[self.library].items():
                self.offer(n, what)
        if wrap:
            self.tokens.append(")")
        self.commas, self.in_scene, self.nesting, self.in_model = saved[2], saved[4], saved[5], saved[6]
        if name in ("load_stmt", "prim_call"):
            self.library, self.plan = saved[:2]
        if name == "primitive_def":
            self.prim_now = saved[3]

    def repeat(self, name: str, depth: int, kind) -> None:
        """A repetition: ``kind`` may be a list giving each item's kind (and so the count)."""
        rules = self.g.rules[name]
        base = [r for r in rules if r.expansion[0].name != name]
        more = [r for r in rules if r.expansion[0].name == name]
        if isinstance(kind, list):
            kinds = kind
        else:
            count = 1
            limit = {"__start_star_1": 14}.get(name, 3 if depth < self.MAX_DEPTH // 2 else 1)
            p_more = 0.8 if name == "__start_star_1" else 0.35
            while count < limit and depth < self.MAX_DEPTH and self.rng.random() < p_more:
                count += 1
            kinds = [kind] * count
        for i, k in enumerate(kinds):
            # Separators (";") after an item are rare: the newline usually does it.
            rule = self.pick(
                [
                    (0.15 if any(s.name == "__start_star_0" for s in r.expansion) else 1.0, r)
                    for r in (base if i == 0 else more)
                ]
            )
            for sym in [s.name for s in rule.expansion][0 if i == 0 else 1 :]:
                if self.g.is_terminal(sym):
                    self.tokens.append(self.terminal(sym, k, {}))
                else:
                    self.expand(sym, depth + 1, k)

    # ------------------------------------------------------------ weights
    def weight(self, name: str, rule, kind, depth: int) -> float:
        """How likely this expansion is, here."""
        symbols = [s.name for s in rule.expansion]
        # Leading separators (";") are legal but rare in real programs.
        rare = 0.2 if "__start_star_0" in symbols else 1.0
        return rare * self._weight(name, rule, symbols, kind, depth)

    def _weight(self, name: str, rule, symbols: list, kind, depth: int) -> float:
        alias = rule.alias
        head = symbols[0] if symbols else ""
        deep = depth > self.MAX_DEPTH * 0.6
        if name == "start":
            return 10.0 if "__start_star_1" in symbols else 0.2
        if name == "top":
            return {"statement": 30.0, "primitive_def": 0.6}.get(head, 0.2)
        if name == "statement":
            return self._statement_weight(head, deep)
        if name == "pat_item" and self.pattern_items == 0:
            return 1.0 if head == "STRING" else 0.01
        if name == "_prim_item":  # the pattern first
            return (1.0 if head == "statement" else 0.1) if self.prim_pattern else (0.2 if head == "statement" else 5.0)
        if name == "joint_args":  # at least one extreme pair; SLIDE and AXIS now and then
            w = 1.0 if len(symbols) > 9 else 0.01
            return w * (0.3 if "SLIDE" in symbols else 1.0) * (0.3 if "joint_axis" in symbols else 1.0)
        if name in ("model_block", "motion_block", "reach_block", "primitive_def"):
            return 1.0 if any(s.startswith("__") and s != "__start_star_0" for s in symbols) else 0.01
        if name in ("_prim_head", "_load_name"):
            return 10.0 if head == "NAME" else 1.0
        if name == "rhs":
            return {
                "expr": 5.0,
                "joint_expr": 4.0 if kind == MODEL else 0.1,
                "strip_expr": 1.5 if kind == MOTION else 0.1,
                "sync_expr": 1.5 if kind == MOTION else 0.1,
            }[head]
        if name in ("atom", "catom"):
            w = _atom_weight(alias, symbols, kind) * (0.3 if deep and len(symbols) > 1 else 1.0)
            if self.in_model and kind == GRAPH and alias != "var":
                w *= 0.001  # a model block's joints name their segments
            return w
        if name in ("sum", "csum", "product", "cproduct"):
            if len(symbols) == 1:
                return 6.0
            if self.in_model and kind == GRAPH:
                return 0.001
            # What the checker allows: G + G, W + W, n * W, v * n, v / n.
            allowed = {GRAPH: ("add",), MODEL: (), MOTION: ("add", "mul"), VEC: ("add", "sub", "mul", "div")}
            if kind in allowed and alias not in allowed[kind]:
                return 0.005
            if deep or kind in (GRAPH, MOTION):
                return 0.05
            return 0.6 if alias in ("add", "sub", "mul") else 0.3
        if name in ("unary", "cunary"):
            if len(symbols) > 1 and kind in (GRAPH, MODEL, MOTION):
                return 0.005
            return 12.0 if len(symbols) == 1 else (1.0 if alias == "neg" else 0.2)
        if name == "postfix":
            if len(symbols) == 1 or (self.in_model and kind == GRAPH):
                return 6.0 if len(symbols) == 1 else 0.001
            return {GRAPH: 2.5, MODEL: 2.5, MOTION: 1.5, None: 0.1}.get(kind, 0.03)
        if name == "modifier":
            return _MODIFIER_WEIGHTS.get(kind, {}).get(alias, 0.1 if kind in _MODIFIER_WEIGHTS else 1.0)
        if name in ("cond", "cond_and", "cond_not"):
            return 6.0 if len(symbols) == 1 else 1.0
        if name == "compare":
            return 6.0 if len(symbols) == 3 else 1.0
        if name == "print_item":
            return {None: 4.0, "print_table": 1.0, "print_text": 2.0}[alias]
        if name == "prim_call":
            return {1: 0.3, 2: 3.0}.get(len(symbols), 6.0)
        return 1.0

    def _statement_weight(self, head: str, deep: bool) -> float:
        w = _STATEMENT_WEIGHTS.get(head, 1.0)
        if head == "continue_stmt" and self.labels:
            w = 3.0
        if self.in_scene and head in ("view_stmt", "background_stmt", "animate_stmt"):
            w = 3.0
        if self.in_scene and head in ("shoot_stmt", "scene_block"):
            w = 0.01
        if self.prim_now and head in ("draw_with", "draw_poly"):
            w = 4.0
        if self.prim_now and head == "return_stmt":
            w = 0.5
        if self.nesting and head in ("load_stmt", "scene_block", "shoot_stmt"):
            w = 0.01
        if deep and head in _BLOCKS:
            w *= 0.1
        return w

    # ------------------------------------------------------------ kinds
    def child_kind(self, name: str, rule, symbols: list, i: int, kind, local: dict):
        """The kind of value symbol ``i`` of this expansion should produce (a list for a repetition)."""
        sym = symbols[i]
        prev = symbols[i - 1] if i else ""
        rng = self.rng
        many = sym.startswith("__")
        if name in ("assignment", "declaration"):
            return local.get("kind")
        if name in ("keyframe_assign", "keyframe", "motion_joint", "do_stmt", "figure_stmt", "scene_block"):
            return INT if sym == "expr" else None
        if name == "position":  # one vector, or three numbers
            return VEC if len(symbols) == 1 else ([NUM, NUM] if many else NUM)
        if name == "if_stmt" and sym == "cond":
            return COND
        if name == "joint_args":
            if many:
                return [PAIR] * rng.randrange(3)
            if sym == "joint_axis":
                return None
            return [INT, GRAPH, VEC, GRAPH, VEC][i // 2] if i < 9 else PAIR
        if name == "joint_axis":
            return VEC
        if name == "reach_block":
            return {"MODEL_KW": MODEL, "FRAME": INT, "FROM": MOTION}.get(prev)
        if name in ("goal_spec", "goal_point", "goal_plane", "goal_axis"):
            return VEC
        if name == "reach_item":
            if many:
                return [INT] * (1 + rng.randrange(2))
            return {"WEIGHT": NUM, "JOINTS": INT, "CHAIN": INT, "TOLERANCE": NUM, "ITERATIONS": INT}.get(prev)
        if name == "animate_stmt":
            return MOTION if prev == "USING" else (INT if sym == "expr" else None)
        if name == "background_stmt":
            return [GRAPH] * (1 + rng.randrange(2)) if many else GRAPH
        if name == "view_stmt":
            return VEC if symbols[1] == "POINT" else NUM
        if name == "draw_poly":
            return [VEC] * (1 + rng.randrange(3)) if many else VEC
        if name == "strip_expr":
            return [INT] * (1 + rng.randrange(4)) if many else MOTION
        if name == "sync_expr":
            return [MOTION] * (1 + rng.randrange(2)) if many else MOTION
        if name == "modifier":
            return VEC if prev == "TRANS" else NUM  # TRANS JOINTS BY takes a joint number
        if name in ("atom", "catom"):
            return self._atom_child(rule, symbols, i, kind, local)
        if name == "prim_call":
            return [None] * max(1, len(self.plan)) if many else None
        if name == "prim_clause":
            return local.get("kind", NUM)
        if name in ("compare", "cond", "cond_and", "cond_not"):
            return NUM if sym == "cexpr" else COND
        if name in ("product", "cproduct") and rule.alias == "mod":
            return NUM
        if name in ("product", "cproduct") and kind == MOTION and sym.endswith("product"):
            return INT  # 2 * WALK
        if name in ("product", "cproduct") and kind == VEC and rule.alias in ("mul", "div") and sym.endswith("unary"):
            return NUM  # v * n, v / n
        return None if isinstance(kind, list) else kind

    def _atom_child(self, rule, symbols: list, i: int, kind, local: dict):
        sym = symbols[i]
        if rule.alias == "call":
            args = _FUNCTIONS.get(local.get("function", ""), ([NUM, NUM], NUM))[0]
            if sym.startswith("__"):
                return list(args[1:]) or [NUM]
            return args[0] if sym in ("expr", "cexpr") else None
        if rule.alias == "tuple":
            count = {VEC: 3, PAIR: 2}.get(kind, 2 + self.rng.randrange(2))
            return [NUM] * (count - 1) if sym.startswith("__") else NUM
        return kind

    # ------------------------------------------------------------ terminals
    def terminal(self, sym: str, kind, local: dict, rule: str = "", symbols=(), i: int = 0) -> str:
        """The spelling of one token of terminal ``sym``."""
        rng = self.rng
        if sym == "NAME":
            return self.word(rule, symbols, i, kind, local)
        if sym == "PRIM_NAME":
            return self.primitive_name(rule, symbols)
        if sym == "NUMBER":
            if rule == "do_stmt":
                local["label"] = str(self.next_label)
                self.labels.append(local["label"])
                self.next_label += 10
                return local["label"]
            if rule == "continue_stmt":
                return self.labels.pop() if self.labels else str(self.next_label)
            if rule == "goal_link":
                return rng.choice(["1", "2", "3"])
            return self.number(kind)
        if sym == "STRING":
            if rule == "load_stmt":
                # Now and then: no such library, the program itself (a cycle), a folder, a system file.
                odd = ["'nowhere'", "'fuzz.lig'", "'fuzz'", "'.'", "''", "'/etc/hostname'", "'../stdlib/shapes'"]
                return f"'{self.library}'" if rng.random() < 0.93 else rng.choice(odd)
            if rule == "pat_item":
                self.pattern_items += 1
                if self.pattern_items == 1:  # a pattern begins with the primitive's name
                    return f"'{self.prim_now or 'PEG'}'"
                return rng.choice(["'AT'", "','", "'SIZE'", f"'{self.prim_now or 'PEG'}'"])
            return rng.choice(["'hello'", "''", "'A = '", "'°'", "'{'", "'é\u2028'", "'\\n'"])
        if sym == "DOLLAR_NAME":
            return "$" + self.name_of(MODEL)
        if sym == "TYPE_KW":
            word = rng.choice(["INTEGER", "REAL", "VECTOR", "GRAPHICAL", "MODEL", "MOTION"])
            local["kind"] = {
                "INTEGER": INT,
                "REAL": NUM,
                "VECTOR": VEC,
                "GRAPHICAL": GRAPH,
                "MODEL": MODEL,
                "MOTION": MOTION,
            }[word]
            return self.cased(word)
        t = self.g.terminals[sym]
        text = t.pattern.value if t.pattern.type == "str" else sample_regex(t.pattern.value, rng)
        return self.cased(text) if "i" in t.pattern.flags else text

    def primitive_name(self, rule: str, symbols) -> str:
        """A PRIM_NAME token, and the plan of the clauses that follow it in a call."""
        rng = self.rng
        if rule == "_prim_head":
            return self.prim_now or "BOX"
        if rule == "_load_name":
            offered = [n for n, what in self.exports[self.library].items() if isinstance(what, list)]
            return rng.choice(offered or ["BOX"])
        name = rng.choice(sorted(self.prims))
        clauses = self.prims[name]
        slots = {1: 0, 2: 1}.get(len(symbols), 2)
        if rng.random() < 0.75:  # as the pattern has them: required ones, some optional ones, in order
            plan = [c for c in clauses if not c[2] or rng.random() < 0.4]
        else:
            plan = [rng.choice(clauses) for _ in range(1 + rng.randrange(4))]
        while len(plan) < slots:
            plan.append(rng.choice(clauses))
        self.plan = plan[:slots] if slots < 2 else plan
        return name

    def word(self, rule: str, symbols, i: int, kind, local: dict) -> str:
        """A NAME: a variable, function, model, motion, link, clause word... as the rule wants."""
        rng = self.rng
        if rule == "assignment":
            name = self.name_of(None) if rng.random() < 0.93 else rng.choice(["T", "U", "NEWVAR"])
            local["kind"] = self.kind_of(name)
            return name
        if rule == "decl_name":
            k = kind or NUM
            if rng.random() < 0.6:
                name = f"{'X' if k in (NUM, INT) else k}{len(self.names.get(k, [])) + 1}"
                self.names.setdefault(k, []).append(name)
                return name
            return self.name_of(k)
        if local.get("alias") == "reach_solver":
            return rng.choice(_SOLVERS)
        if local.get("alias") == "reach_translate":
            return self.name_of(VEC)
        if rule in ("keyframe_assign", "motion_block", "reach_block"):
            return self.name_of(MOTION)
        if rule in ("model_block", "animate_stmt") or (rule == "figure_stmt" and i == 1):
            return self.name_of(MODEL)
        if rule in ("figure_stmt", "goal_link", "reach_item"):
            return self.name_of(GRAPH)
        if rule == "interpolate":
            return rng.choice(_INTERPOLATIONS)
        if rule == "do_stmt":
            return self.name_of(INT) if rng.random() < 0.8 else self.name_of(NUM)
        if rule in ("atom", "catom") and len(symbols) > 1:
            one = len(symbols) == 4
            arity = [f for f, (args, _) in _FUNCTIONS.items() if (len(args) == 1) == one]
            fits = [f for f in arity if kind in (None, INT, COND) or _FUNCTIONS[f][1] == kind]
            name = rng.choice(fits or arity)
            local["function"] = name
            return name
        if rule == "prim_clause":
            word, k, _ = self.plan.pop(0) if self.plan else rng.choice(_BOX)
            local["kind"] = k
            return word
        if rule == "_load_name":
            offered = self.exports.get(self.library, {})
            name = rng.choice(sorted(offered) or ["NOTHING"])
            self.offer(name, offered.get(name))
            return name
        if rule == "_prim_head":
            if self.prim_now is None:
                self.prim_now = rng.choice(_PRIMITIVE_HEADS)
                self.prims[self.prim_now] = [(p, NUM, False) for p in _PARAMS]
            return self.prim_now
        if rule in ("pat_item", "pat_default"):
            return rng.choice(_PARAMS)
        return self.name_of(kind if kind in PRELUDE_NAMES else None)


def _atom_weight(alias, symbols: list, kind) -> float:
    if alias == "number":
        return {NUM: 5.0, None: 3.0, COND: 5.0}.get(kind, 0.1)
    if alias == "var":
        return 5.0 if kind is not None else 3.0
    if alias == "call":
        return {NUM: 1.5, None: 1.0, COND: 1.0, VEC: 0.2}.get(kind, 0.05)
    if alias == "tuple":
        return {VEC: 6.0, PAIR: 6.0, None: 1.0}.get(kind, 0.05)
    if symbols and symbols[0] == "prim_call":
        return {GRAPH: 3.0, None: 0.5}.get(kind, 0.005)
    inner = symbols[1] if len(symbols) > 1 else ""
    if inner == "joint_expr":
        return 1.0 if kind == MODEL else 0.03
    if inner in ("strip_expr", "sync_expr"):
        return 1.0 if kind == MOTION else 0.03
    return 0.5  # ( expr )


#: Rare layout between tokens: a continuation line, comments (one with a
#: line separator, one spanning lines), a tab, a form feed.
_ODD_BLANKS = ["\n" + " " * 9, " { a comment } ", " {é ° \u2028 x} ", " {two\n lines} ", "\t", "\f "]
#: Rare lines between statements: a FORTRAN comment, a blank line with spaces, a CRLF line end.
_ODD_LINES = ["\nC a comment line", "\nc  ROT X 1e309 {", "\n   \t ", "\r"]


def layout(tokens: list, rng) -> str:
    """Join tokens with blanks; a statement starts a new, indented line (column 1 is for C comments).

    Now and then the layout is odd (comments, tabs, CR, a line flagged
    with ``*`` in column 1, as the thesis' listings flag extensions).
    """
    indent = "      "
    out = [indent]
    for tok in tokens:
        if tok is None:
            if len(out) > 1:
                r = rng.random()
                if r < 0.02:
                    out.append(rng.choice(_ODD_LINES))
                out.append("\n" + ("*" + indent[1:] if r > 0.99 else indent) + " " * rng.randrange(4))
            continue
        if len(out) > 1 and not out[-1].startswith("\n"):
            out.append(" " if rng.random() < 0.98 else rng.choice(_ODD_BLANKS))
        out.append(tok)
    return "".join(out).rstrip() + "\n"


def grammar_program(rng, wild: tuple = (), wild_rate: float = 0.0) -> str:
    """A random program expanded from lang/lig.lark (see the module's docstring).

    Most programs start with a prelude that declares, and usually assigns,
    the names the expansion draws from. A number slot takes one of ``wild``
    (number tokens or parenthesised expressions) with probability ``wild_rate``.
    """
    r = rng.random()
    prelude = "" if r < 0.1 else (DECLARATIONS if r < 0.3 else DECLARATIONS + VALUES)
    ex = Expander(
        rng, PRELUDE_NAMES if prelude else {k: v[:1] for k, v in PRELUDE_NAMES.items()}, tuple(wild), wild_rate
    )
    ex.expand("start", 0)
    while ex.labels and rng.random() < 0.9:
        ex.tokens += [None, ex.labels.pop(), "CONTINUE"]
    if rng.random() < 0.5:
        ex.tokens += [None, "SHOOTSCENES"]
    return prelude + layout(ex.tokens, rng)
