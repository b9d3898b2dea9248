# Stands in for a machine without python3-matplotlib: on PYTHONPATH, `import matplotlib` fails.
raise ImportError("No module named 'matplotlib' (stand-in of tests/cli/no_matplotlib)")
