@ Hand-written code the compiler does not produce at -O2 (each reached from its own root,
@ see case_asm.cpp): a function that runs off its end into the next one, as libgcc's
@ __aeabi_dsub does; a linker-style veneer (ldr pc, [pc, #imm]); a function address built
@ with movw/movt, then called through a register; an interrupt vector with no symbol, which
@ only the name of its section marks as a vector; a switch's table jump as GCC writes it at
@ -Os (adr, then ldr pc through the table), one of its cases calling a double function; the
@ same jump through a table whose word is another function's address (a call, not a switch).
  .syntax unified
  .thumb

  .section .text.asm_fall,"ax",%progbits
  .global asm_fall_a
  .type asm_fall_a, %function
  .thumb_func
asm_fall_a:
  adds r0, r0, #1             @ no return: execution continues in asm_fall_b
  .size asm_fall_a, .-asm_fall_a
  .global asm_fall_b
  .type asm_fall_b, %function
  .thumb_func
asm_fall_b:
  push {r3, lr}
  bl malloc
  pop {r3, pc}
  .size asm_fall_b, .-asm_fall_b

  .section .text.asm_veneer,"ax",%progbits
  .balign 4
  .global asm_veneer
  .type asm_veneer, %function
  .thumb_func
asm_veneer:
  ldr.w pc, [pc, #0]          @ jumps to the word below
  .word far_double            @ the linker sets the Thumb bit
  .size asm_veneer, .-asm_veneer

  .section .text.asm_movw_call,"ax",%progbits
  .global asm_movw_call
  .type asm_movw_call, %function
  .thumb_func
asm_movw_call:
  push {r3, lr}
  movw r3, #:lower16:movw_target
  movt r3, #:upper16:movw_target
  blx r3
  pop {r3, pc}
  .size asm_movw_call, .-asm_movw_call

  .section .text.asm_switch,"ax",%progbits
  .global asm_switch
  .type asm_switch, %function
  .thumb_func
asm_switch:
  push {r3, lr}
  cmp r0, #2
  bhi 3f
  adr r1, 0f
  ldr.w pc, [r1, r0, lsl #2]
  .balign 4
0:
  .word 1f+1
  .word 2f+1
  .word 3f+1
1:
  bl far_double
  pop {r3, pc}
2:
  adds r0, r0, #1
3:
  pop {r3, pc}
  .size asm_switch, .-asm_switch

  .section .text.asm_table_out,"ax",%progbits
  .global asm_table_out
  .type asm_table_out, %function
  .thumb_func
asm_table_out:
  adr r1, 0f
  ldr.w pc, [r1, r0, lsl #2]
  .balign 4
0:
  .word movw_target           @ the linker sets the Thumb bit
  .size asm_table_out, .-asm_table_out

  @ No data object: only fixture_sections.ld, which keeps .isr_vector an output section,
  @ shows that this word is a vector (fixture_text.ld merges it into .text).
  .section .isr_vector.irq,"a",%progbits
  .word asm_irq_handler
