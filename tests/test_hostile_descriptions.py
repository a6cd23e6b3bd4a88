"""Hostile xacro files (issue 31, item 3): each attack gives one clear error line (exit 2) and runs nothing.

The PyPI xacro library evaluates ``${...}`` with ``eval`` and forbids only names starting with ``__`` at the
expression's top level: a lambda or a generator expression reaches ``os.system`` through the frames of objects,
and ``xacro.load_yaml`` reads any file. pinmob evaluates every expression itself (pinmob/io/xacro_expressions.py)
and confines what the library reads (pinmob/io/xacro_file.py). Each attack below would create the file MARKER if
anything ran; each must leave it absent and print one line naming the file and what was refused.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from test_cad_gaps import pinmob_cli

import pinmob
from pinmob.io.xacro_expressions import ExpressionError, evaluate
from pinmob.io.xacro_file import expand_xacro

HEAD = '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="x">'


ATTACKS = {
    # a lambda: its __globals__ are the module's, and through them the real builtins
    "lambda": "<link name=\"${(lambda: 0).__globals__['__builtins__']['__import__']('os').system('touch {marker}')}\"/>",
    # a generator expression: its frame's builtins (names with __ are only checked at the top level by xacro)
    "generator": "<link name=\"${[g for g in [(x for x in [1])]][0].gi_frame.f_builtins['__import__']('os').system('touch {marker}')}\"/>",
    "subclasses": "<link name=\"${[c for c in ().__class__.__base__.__subclasses__() if c.__name__ == 'Popen'][0]('touch {marker}', shell=True)}\"/>",
    "load_yaml": "<link name=\"${xacro.load_yaml('/etc/passwd')}\"/>",
    "include": '<xacro:include filename="/etc/passwd"/>',
    "env": '<link name="$(env HOME)"/>',
    "optenv": '<link name="$(optenv HOME nothing)"/>',
    "eval extension": "<link name=\"$(eval __import__('os').system('touch {marker}'))\"/>",
    "power": '<link name="${9**9**9}"/>',
    "string": '<xacro:property name="s" value="${\'ab\' * 10**8}"/><link name="${s}"/>',
    "factorial": '<link name="${factorial(10**8)}"/>',
    "namespace item": "<link name=\"${xacro['load_yaml']}\"/>",  # a function of xacro's namespace, as a value  # hours of arithmetic, no large value until the end
    "nested list": '<link name="${[[0] * 100000] * 100000}"/>',  # each list bounded, their product not
    # properties the library joins from pieces: 2^40 characters from 40 lines
    "joined": '<xacro:property name="p0" value="aaaaaaaaaa"/>'
    + "".join(f'<xacro:property name="p{k}" value="${{p{k - 1}}}${{p{k - 1}}}"/>' for k in range(1, 40))
    + '<link name="${p39}"/>',
}
SAID = {
    "lambda": "not allowed",
    "generator": "not allowed",
    "subclasses": "not allowed",
    "load_yaml": "is outside the folders pinmob reads",
    "include": "is outside the folders pinmob reads",
    "env": "$(env ...) is not allowed",
    "optenv": "$(optenv ...) is not allowed",
    "eval extension": "$(eval ...) is not allowed",
    "power": "an exponent over 1000",
    "string": "a result over 100000 items",
    "factorial": "factorial",
    "namespace item": "is not a value",
    "nested list": "over 100000 items (nested)",
    "joined": "a result of",
}


def refused(path: Path, *args: str) -> str:
    """The one line of ``pinmob analyze path`` (asserting exit 2, nothing on stdout, no traceback)."""
    done = pinmob_cli("analyze", str(path), *args)
    assert done.returncode == 2 and done.stdout == "", (done.stdout, done.stderr)
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr, done.stderr
    assert str(path) in done.stderr
    return done.stderr


@pytest.mark.parametrize("attack", sorted(ATTACKS))
def test_an_attack_runs_nothing_and_says_so_in_one_line(tmp_path, attack):
    marker = tmp_path / "MARKER"
    path = tmp_path / "evil.urdf.xacro"
    path.write_text(HEAD + ATTACKS[attack].replace("{marker}", str(marker)) + "</robot>")
    line = refused(path)
    assert SAID[attack] in line, line
    assert not marker.exists()


def test_xml_entities_are_refused(tmp_path):
    """The billion laughs: ten entities of ten references each."""
    lol = "".join(f'<!ENTITY l{k} "{f"&l{k - 1};" * 10}">' for k in range(1, 10))
    path = tmp_path / "laughs.urdf.xacro"
    path.write_text(
        f'<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY l0 "lol">{lol}]>' + HEAD + '<link name="&l9;"/></robot>'
    )
    assert "<!ENTITY> declarations are not read" in refused(path)


def test_macro_laughs_are_bounded(tmp_path):
    """Nine macros each calling the one below ten times: 10^9 links, refused at the macro-call bound."""
    macros = '<xacro:macro name="m0" params="p"><link name="${p}"/></xacro:macro>' + "".join(
        f'<xacro:macro name="m{k}" params="p">'
        + "".join(f'<xacro:m{k - 1} p="${{p}}_{i}"/>' for i in range(10))
        + "</xacro:macro>"
        for k in range(1, 10)
    )
    path = tmp_path / "macros.urdf.xacro"
    path.write_text(HEAD + macros + '<xacro:m9 p="x"/></robot>')
    line = refused(path)
    assert "macro calls" in line and "the expansion is refused" in line, line


def test_includes_and_blocks_that_double_are_bounded(tmp_path):
    """Thirty files each including the next twice (2^30 parses), and thirty macros each inserting their block
    twice into the next (2^30 elements): refused at the bound, in seconds."""
    for k in range(30):
        inner = "" if k == 29 else f'<xacro:include filename="f{k + 1}.xacro"/>' * 2
        (tmp_path / f"f{k}.xacro").write_text(HEAD + f'<link name="l{k}"/>' + inner + "</robot>")
    path = tmp_path / "includes.urdf.xacro"
    path.write_text(HEAD + '<xacro:include filename="f0.xacro"/></robot>')
    done = pinmob_cli("analyze", str(path))  # the line names the included file being read when refused
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and "the expansion is refused" in done.stderr
    blocks = '<xacro:macro name="b0" params="*x"><xacro:insert_block name="x"/></xacro:macro>' + "".join(
        f'<xacro:macro name="b{k}" params="*x"><xacro:b{k - 1}><g><xacro:insert_block name="x"/>'
        f'<xacro:insert_block name="x"/></g></xacro:b{k - 1}></xacro:macro>'
        for k in range(1, 30)
    )
    path = tmp_path / "blocks.urdf.xacro"
    path.write_text(HEAD + blocks + '<xacro:b29><link name="x"/></xacro:b29></robot>')
    assert "the expansion is refused" in refused(path)


def test_deep_recursion_is_one_line(tmp_path):
    path = tmp_path / "recursive.urdf.xacro"
    path.write_text(
        HEAD + '<xacro:macro name="r" params="n"><xacro:r n="${n+1}"/></xacro:macro><xacro:r n="0"/></robot>'
    )
    line = refused(path)
    assert "recursion" in line or "nested too deeply" in line, line


def test_properties_that_double_are_bounded(tmp_path):
    props = '<xacro:property name="p0" value="aaaaaaaaaa"/>' + "".join(
        f'<xacro:property name="p{k}" value="${{p{k - 1} + p{k - 1}}}"/>' for k in range(1, 40)
    )
    path = tmp_path / "doubling.urdf.xacro"
    path.write_text(HEAD + props + '<link name="${p39}"/></robot>')
    assert "a result of" in refused(path)


def test_load_yaml_and_includes_inside_the_folders_are_read(tmp_path):
    """What is allowed still works: a YAML file and an include beside the xacro file, a package's file."""
    (tmp_path / "p.yaml").write_text("arm: {length: 0.25}\n")
    pkg = tmp_path / "pkgs" / "robot_description"
    pkg.mkdir(parents=True)
    (pkg / "parts.xacro").write_text(HEAD + '<xacro:property name="w" value="3"/></robot>')
    path = tmp_path / "ok.urdf.xacro"
    path.write_text(
        HEAD + '<xacro:include filename="$(find robot_description)/parts.xacro"/>'
        '<xacro:property name="c" value="${xacro.load_yaml(\'p.yaml\')}"/>'
        "<link name=\"l_${c.arm.length * w}_${c['arm']['length']}\"/></robot>"
    )
    assert '<link name="l_0.75_0.25"/>' in expand_xacro(path, {}, [tmp_path / "pkgs"])


@pytest.mark.parametrize(
    "expr",
    ["(lambda: 1)()", "[x for x in (1,)]", "{1: 2}", "f'{1}'", "(y := 1)", "open('x')", "max(*[1, 2])", "a.__class__"],
)
def test_the_evaluator_refuses_before_evaluating(expr):
    with pytest.raises(ExpressionError):
        evaluate(expr, {"a": 1})


def test_the_python_api_refuses_the_same(tmp_path):
    path = tmp_path / "evil.urdf.xacro"
    path.write_text(HEAD + '<link name="$(env HOME)"/></robot>')
    with pytest.raises(pinmob.MechanismFileError, match=r"\$\(env \.\.\.\) is not allowed"):
        pinmob.load(path)
