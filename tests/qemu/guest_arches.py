"""The guest architectures the qemu tier boots (qemu_guest.py --arch)."""

# Per guest architecture: Debian's name for it, QEMU's command line, the serial console's name,
# and the ELF machine number its programs carry (to reject an x86 binary shipped to an arm guest).
ARCHES = {
    "x86_64": {
        "debian": "amd64",
        # The default PC machine; its 16550 UART is ttyS0, ACPI makes `poweroff -f` end QEMU.
        "qemu_args": ["-M", "pc"],
        "console": "ttyS0",
        "elf_machine": 62,  # EM_X86_64
    },
    "aarch64": {
        "debian": "arm64",
        # `virt` has the PL011 UART (ttyAMA0), PSCI for power-off, and the PL061 GPIO controller
        # (gpiochip0, 8 lines; line 3 is QEMU's power button). Cortex-A53 because TCG emulates it
        # faster than `max` (no pointer authentication to emulate).
        "qemu_args": ["-M", "virt", "-cpu", "cortex-a53"],
        "console": "ttyAMA0",
        "elf_machine": 183,  # EM_AARCH64
    },
}
