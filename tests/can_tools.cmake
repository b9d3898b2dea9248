# CAN tool tests (filled in below)
