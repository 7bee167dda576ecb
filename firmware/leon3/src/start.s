! Start-up and register-window traps of a bare-metal SPARC V8 (LEON3, 8 windows).
! Trap table: reset and every trap not handled -> bad_trap (prints '!' and stops);
! window overflow (tt 5) and underflow (tt 6) spill and fill one window to and from
! the stack (the classic handlers of the SPARC V8 manual's appendix / LEON BCC).

        .section .text.traps, "ax"
        .align 4096
        .global trap_table
trap_table:
        ba      _start                  ! tt 0x00: reset
        nop
        nop
        nop
        .rept 4                         ! tt 0x01-0x04
        ba      bad_trap
        rd      %psr, %l0
        nop
        nop
        .endr
        ba      window_overflow         ! tt 0x05
        rd      %psr, %l0
        nop
        nop
        ba      window_underflow        ! tt 0x06
        rd      %psr, %l0
        nop
        nop
        .rept 249                       ! tt 0x07-0xff
        ba      bad_trap
        rd      %psr, %l0
        nop
        nop
        .endr

        .section .text.start, "ax"
        .align 4
        .global _start
_start:
        ! Supervisor, traps off, PIL 15, FPU on (EF), window 0.
        set     0x10c0 | 0x0f00, %g1
        wr      %g1, %psr
        nop
        nop
        nop
        ! Window 1 invalid: the trap window below window 0.
        mov     2, %g1
        wr      %g1, %wim
        nop
        nop
        nop
        set     trap_table, %g1
        wr      %g1, %tbr
        nop
        nop
        nop
        set     __stack_top, %sp
        sub     %sp, 96, %sp
        mov     %g0, %fp
        ! FSR = 0: round to nearest, no FP traps enabled.
        st      %g0, [%sp + 64]
        ld      [%sp + 64], %fsr
        nop
        ! Zero .bss.
        set     __bss_start, %g2
        set     __bss_end, %g3
1:      cmp     %g2, %g3
        bgeu    2f
        nop
        st      %g0, [%g2]
        ba      1b
        add     %g2, 4, %g2
2:      ! Traps on.
        rd      %psr, %g1
        or      %g1, 0x20, %g1
        wr      %g1, %psr
        nop
        nop
        nop
        call    rust_main
        nop
3:      ba      3b
        nop

window_overflow:
        mov     %wim, %l3
        mov     %g1, %l7
        srl     %l3, 1, %g1
        sll     %l3, 7, %l4
        or      %l4, %g1, %g1
        and     %g1, 0xff, %g1
        save
        mov     %g1, %wim
        nop
        nop
        nop
        std     %l0, [%sp + 0]
        std     %l2, [%sp + 8]
        std     %l4, [%sp + 16]
        std     %l6, [%sp + 24]
        std     %i0, [%sp + 32]
        std     %i2, [%sp + 40]
        std     %i4, [%sp + 48]
        std     %i6, [%sp + 56]
        restore
        mov     %l7, %g1
        jmp     %l1
        rett    %l2

window_underflow:
        mov     %wim, %l3
        sll     %l3, 1, %l4
        srl     %l3, 7, %l5
        or      %l5, %l4, %l5
        and     %l5, 0xff, %l5
        mov     %l5, %wim
        nop
        nop
        nop
        restore
        restore
        ldd     [%sp + 0], %l0
        ldd     [%sp + 8], %l2
        ldd     [%sp + 16], %l4
        ldd     [%sp + 24], %l6
        ldd     [%sp + 32], %i0
        ldd     [%sp + 40], %i2
        ldd     [%sp + 48], %i4
        ldd     [%sp + 56], %i6
        save
        save
        jmp     %l1
        rett    %l2

bad_trap:
        set     0x80000100, %l4
        mov     0x21, %l5
        st      %l5, [%l4]
4:      ba      4b
        nop

! Stops the emulator: traps off, then `ta 0` (trap 0x80 with traps disabled: QEMU's
! LEON3 model shuts down on it, exit status 0; real hardware enters error mode).
        .global leon3_shutdown
leon3_shutdown:
        rd      %psr, %g1
        andn    %g1, 0x20, %g1
        wr      %g1, %psr
        nop
        nop
        nop
        ta      0
5:      ba      5b
        nop
