//! # trocar-qemu — the embedded examples on a Cortex-M4F under QEMU
//!
//! Two programs for QEMU's `mps2-an386` board (Cortex-M4F, `thumbv7em-none-eabihf`), each
//! running a fixed sequence of control steps and printing, over semihosting, every step's rates
//! as the bits of their `f32`s, its instruction count, and at the end the stack depth of a step:
//!
//! - `firmware`: `trocar-firmware`'s DLS step on the generated `dia10_like_zy` kinematics;
//! - `panda`: `trocar-panda`'s runtime controller on the generated Panda kinematics, its DLS step
//!   on the circle of the `panda-laparoscope` scenario and its QP step with hard limits on the
//!   path of `panda-laparoscope-limits`.
//!
//! `examples/firmware/run-qemu.sh` builds and runs them and compares each step with the host's
//! run of the same code (`examples/panda/tests/matches_qemu.rs`,
//! `examples/firmware/tests/matches_qemu.rs`).
//!
//! Instruction counts: QEMU runs with `-icount shift=6`, so its virtual clock advances 64 ns per
//! instruction executed, and SysTick, clocked from it, counts instructions
//! ([`InstructionCounter`], calibrated against a block of a known number of instructions at
//! start). A count is deterministic; it is not a cycle count (see `BENCHMARKS.md`).
#![no_std]

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_semihosting::debug;

pub use cortex_m_semihosting::hprintln;

/// Counts instructions with SysTick under `-icount` (see the [crate](crate) documentation).
pub struct InstructionCounter {
    _syst: SYST,
    /// Instructions per 1024 ticks, from the calibration.
    per_1024_ticks: u64,
}

/// The instructions of the calibration block (`nop`s).
const CALIBRATION: u64 = 4096;

impl InstructionCounter {
    /// SysTick counting down from `2²⁴ − 1` on the core clock, calibrated.
    pub fn new(mut syst: SYST) -> Self {
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(0x00ff_ffff);
        syst.clear_current();
        syst.enable_counter();
        let mut counter = InstructionCounter {
            _syst: syst,
            per_1024_ticks: 1024,
        };
        // The same read–block–read with and without the block: the difference is the block.
        let empty = counter.ticks(|| ());
        let block = counter.ticks(|| {
            // SAFETY: `nop`s only: no memory, registers or flags touched.
            unsafe { core::arch::asm!(".rept 4096", "nop", ".endr", options(nomem, nostack)) }
        });
        let ticks = block.saturating_sub(empty).max(1);
        counter.per_1024_ticks = CALIBRATION * 1024 / ticks;
        counter
    }

    fn now(&self) -> u32 {
        SYST::get_current()
    }

    /// SysTick's ticks while `f` runs (less than `2²⁴`).
    pub fn ticks(&mut self, f: impl FnOnce()) -> u64 {
        let start = self.now();
        f();
        let end = self.now();
        u64::from(start.wrapping_sub(end) & 0x00ff_ffff)
    }

    /// The instructions `f` executed (to within the counter's resolution, below one
    /// instruction at `shift=6`), and `f`'s result.
    pub fn count<R>(&mut self, f: impl FnOnce() -> R) -> (u64, R) {
        let mut result = None;
        let ticks = self.ticks(|| result = Some(f()));
        let per = self.per_1024_ticks;
        // `f` ran: `result` holds its value.
        (
            (ticks * per + 512) / 1024,
            result.unwrap_or_else(|| fail("the counted closure did not run")),
        )
    }

    /// Instructions per 1024 SysTick ticks (the calibration's result).
    pub fn per_1024_ticks(&self) -> u64 {
        self.per_1024_ticks
    }
}

/// The program's start: the core peripherals taken, the [`InstructionCounter`] set up and its
/// calibration printed.
pub fn start() -> InstructionCounter {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        fail("the core peripherals were taken");
    };
    let counter = InstructionCounter::new(peripherals.SYST);
    hprintln!(
        "calibration {} instructions per 1024 ticks",
        counter.per_1024_ticks()
    );
    counter
}

/// The stack's deepest use, by painting: [`StackGauge::paint`] fills the free stack below the
/// caller with a pattern, [`StackGauge::depth_below`] finds the lowest word overwritten since.
pub struct StackGauge {
    bottom: usize,
}

const PAINT: u32 = 0x5AA5_C33C;

extern "C" {
    // `cortex-m-rt`'s linker script: the first address after the static data (the stack grows
    // down toward it).
    static mut __sheap: u32;
}

impl StackGauge {
    /// Paints the stack from its bottom to 256 bytes below the current stack pointer.
    #[inline(never)]
    pub fn paint() -> Self {
        let bottom = core::ptr::addr_of_mut!(__sheap) as usize;
        let sp = cortex_m::register::msp::read() as usize;
        let top = sp.saturating_sub(256) & !3;
        let mut a = (bottom + 3) & !3;
        while a < top {
            // SAFETY: `a` is word-aligned and between the end of the static data and 256 bytes
            // below the stack pointer: memory of the stack that no live frame uses (the
            // frames of this call and its callers are above `sp`, and this function's own
            // locals are in registers or within the 256 bytes left).
            unsafe { core::ptr::write_volatile(a as *mut u32, PAINT) };
            a += 4;
        }
        StackGauge {
            bottom: (bottom + 3) & !3,
        }
    }

    /// Bytes of stack used below `sp` (a stack pointer read before the measured calls) since
    /// [`Self::paint`].
    pub fn depth_below(&self, sp: usize) -> usize {
        let mut a = self.bottom;
        while a < sp {
            // SAFETY: word-aligned, between the end of the static data and `sp`: stack memory
            // that exists; a read of it changes nothing.
            if unsafe { core::ptr::read_volatile(a as *const u32) } != PAINT {
                return sp - a;
            }
            a += 4;
        }
        0
    }
}

/// The current stack pointer.
pub fn stack_pointer() -> usize {
    cortex_m::register::msp::read() as usize
}

/// Prints `message` and ends QEMU with a failure.
pub fn fail(message: &str) -> ! {
    hprintln!("error: {}", message);
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// Ends QEMU with success.
pub fn exit_success() -> ! {
    debug::exit(debug::EXIT_SUCCESS);
    #[allow(clippy::empty_loop)]
    loop {}
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// A line of text built in place (no allocation), printed with one semihosting call.
struct Line {
    bytes: [u8; 160],
    len: usize,
}

impl core::fmt::Write for Line {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len + s.len();
        let room = self.bytes.get_mut(self.len..end).ok_or(core::fmt::Error)?;
        room.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// Prints one step's line, `step <run> k status instructions qd…`, the rates as the eight hex
/// digits of their `f32` bits (what the host's comparison parses).
pub fn print_step(run: &str, k: usize, status: u32, instructions: u64, qd: &[f32]) {
    use core::fmt::Write as _;
    let mut line = Line {
        bytes: [0; 160],
        len: 0,
    };
    let mut written = write!(line, "step {run} {k} {status} {instructions}");
    for v in qd {
        written = written.and_then(|()| write!(line, " {:08x}", v.to_bits()));
    }
    match (written, core::str::from_utf8(&line.bytes[..line.len])) {
        (Ok(()), Ok(text)) => hprintln!("{}", text),
        _ => fail("a step's line does not fit its buffer"),
    }
}

/// Median, mean (rounded) and largest of `counts` (sorted in place).
pub fn median_mean_max(counts: &mut [u64]) -> (u64, u64, u64) {
    counts.sort_unstable();
    match counts {
        [] => (0, 0, 0),
        _ => {
            let n = counts.len() as u64;
            let sum: u64 = counts.iter().sum();
            (
                counts[counts.len() / 2],
                (sum + n / 2) / n,
                counts[counts.len() - 1],
            )
        }
    }
}
