"""The project's 400-line limit for files, on the Python client and its tests. A generated
module may be exempt, when its first lines say so (protocol_table.py: the whole message table,
written by dbc_gen)."""
MAX_LINES = 400
EXEMPT = "exempt from the 400-line limit"


def test_python_files_stay_under_the_line_limit(source_dir):
    files = [*sorted((source_dir / "tools/python").rglob("*.py")),
             *sorted((source_dir / "tests/python").glob("*.py")),
             *sorted((source_dir / "tests/qemu").glob("python_*.py"))]
    assert len(files) > 20
    over = []
    for path in files:
        lines = path.read_text(encoding="utf-8").splitlines()
        if len(lines) >= MAX_LINES and not any(EXEMPT in line for line in lines[:3]):
            over.append(f"{path.relative_to(source_dir)}: {len(lines)} lines")
    assert not over, over
