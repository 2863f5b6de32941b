/* Minimal startup for cross_check on the Arm MPS2 AN386 (Cortex-M4F) under QEMU: vector table, reset handler
 * (copies .data, zeroes .bss, enables the FPU, starts newlib's semihosting I/O, runs main) and a semihosting
 * SYS_EXIT_EXTENDED so that QEMU's exit status is main's return value (0 = PASS, 1 = FAIL). Any fault ends the run
 * with status 3 (never a hang). Linker script: mps2_an386.ld. */
#include <stdint.h>

extern int main(void);
extern void initialise_monitor_handles(void); /* newlib librdimon: opens stdin/stdout/stderr by semihosting */

extern uint32_t __data_load, __data_start__, __data_end__, __bss_start__, __bss_end__, __StackTop;

/* Semihosting call (Arm semihosting 2.0; QEMU: -semihosting-config enable=on,target=native): r0 = operation,
 * r1 = parameter, BKPT 0xAB on M-profile. */
static uint32_t semihosting_call(uint32_t operation, const void* parameter) {
  register uint32_t r0 __asm__("r0") = operation;
  register const void* r1 __asm__("r1") = parameter;
  __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

enum { SYS_WRITE0 = 0x04, SYS_EXIT_EXTENDED = 0x20, ADP_Stopped_ApplicationExit = 0x20026 };

static void __attribute__((noreturn)) semihosting_exit(uint32_t status) {
  const uint32_t block[2] = {ADP_Stopped_ApplicationExit, status};
  for (;;) {
    semihosting_call(SYS_EXIT_EXTENDED, block);
  }
}

void Reset_Handler(void) __attribute__((noreturn));
void Reset_Handler(void) {
  const uint32_t* source = &__data_load;
  uint32_t* target;
  for (target = &__data_start__; target < &__data_end__;) {
    *target++ = *source++;
  }
  for (target = &__bss_start__; target < &__bss_end__;) {
    *target++ = 0;
  }
#if defined(__ARM_FP)
  /* CPACR: full access to coprocessors 10 and 11 (the FPU), before any floating-point instruction */
  *(volatile uint32_t*)0xE000ED88u |= 0xFu << 20;
  __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif
  initialise_monitor_handles();
  semihosting_exit((uint32_t)main());
}

static void Fault_Handler(void) {
  semihosting_call(SYS_WRITE0, "cross_check: hard fault on the target\nFAIL\n");
  semihosting_exit(3);
}

/* Initial stack pointer, reset, then NMI, HardFault, MemManage, BusFault, UsageFault (all: report and exit). */
__attribute__((section(".vectors"), used)) static void (*const vector_table[])(void) = {
    (void (*)(void))(uintptr_t)&__StackTop, Reset_Handler, Fault_Handler, Fault_Handler, Fault_Handler,
    Fault_Handler, Fault_Handler};
