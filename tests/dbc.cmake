# DBC tests (filled in below)
