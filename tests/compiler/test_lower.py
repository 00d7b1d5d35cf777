"""The lowering: what the generated module does that only running it shows (PRINT labels, positions)."""

import io

import liganimate

DECLARED = "REAL A, B\nVECTOR V\nA = 2\nB = 3\nV = (1, 2, 3)\n"


def printed(body: str) -> list[str]:
    """The lines the program's PRINT statements write."""
    out = io.StringIO()
    liganimate.loads(DECLARED + body).program.check(stdout=out)
    return out.getvalue().splitlines()


def test_a_print_label_is_the_items_own_spelling():
    # The label is the source between the item's first and last characters,
    # parentheses and signs included; the old labels lost a leading "(" or
    # "-" ("A+B)*2", "A" for "-(A)").
    assert printed("PRINT (A+B)*2, -(A), (A), ((A)), + B, (A,B,A), SQRT(A*(B+1)), MAX(A, (B))\n") == [
        "(A+B)*2 = 10",
        "-(A) = -2",
        "(A) = 2",
        "((A)) = 2",
        "+ B = 3",
        "(A,B,A) = (2, 3, 2)",
        "SQRT(A*(B+1)) = 2.82843",
        "MAX(A, (B)) = 3",
    ]


def test_a_label_keeps_spacing_and_case_folds():
    assert printed("PRINT  a  +  (b)  ,v*2\n") == ["A  +  (B) = 5", "V*2 = (2, 4, 6)"]


def test_a_label_written_over_several_lines_is_joined_without_its_comments():
    body = "PRINT (A +   {the first}\n      B) * 2,\n  A +\nC a comment line inside the item\n  B\n"
    assert printed(body) == ["(A + B) * 2 = 10", "A + B = 5"]
