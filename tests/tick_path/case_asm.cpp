// Roots for case_asm.S: SysTick_Handler -> asm_fall_a (falls into asm_fall_b -> malloc),
// PendSV_Handler -> asm_veneer -> far_double, SVC_Handler -> asm_movw_call -> movw_target;
// asm_irq_handler is in an interrupt vector; asm_switch and asm_table_out are roots by name.
extern "C" {
void asm_fall_a();
void asm_veneer(float);
void asm_movw_call(float);
void asm_switch(int);
void asm_table_out(int);

volatile double g_result;

__attribute__((noinline)) void far_double(float x) {
  g_result = x * 0.5;
}
__attribute__((noinline)) void movw_target(float x) {
  g_result = x * 0.25;
}
void asm_irq_handler() {
  g_result = g_result * 2.0;
}

void SysTick_Handler() {
  asm_fall_a();
}
void PendSV_Handler() {
  asm_veneer(1.0f);
}
void SVC_Handler() {
  asm_movw_call(2.0f);
}
volatile int g_case;
void fixture_init() {
  asm_switch(g_case);  // keep them in the image: the cases root them by name
  asm_table_out(g_case);
}
}
