//! Sizing an output buffer for a long plan by what its first steps took.
//!
//! A step's text follows its names, which no estimate made up front knows,
//! and a buffer of tens of megabytes grown by doubling costs more (copies,
//! fresh pages) than writing it. So an emitter writes the first steps into
//! a small buffer, then reserves room for the rest at the rate they took.

/// Steps written before the buffer is sized for the rest.
pub(crate) const SAMPLE_STEPS: usize = 256;

/// How many steps have a node in the main tree: a skipped step has none,
/// and sizing a step node's text by every step would reserve a fifth too
/// much for a plan that skips as many as P3's.
pub(crate) fn steps_with_nodes(ir: &btc_ir::TreeIr) -> usize {
    ir.steps.iter().filter(|s| !s.skipped).count()
}

/// Counts the steps of one run of per-step text (rows, nodes) as they are
/// written and sizes the buffer once the sample is in.
#[derive(Debug)]
pub(crate) struct StepSizer {
    steps: usize,
    written: usize,
    from: usize,
}

impl StepSizer {
    /// A sizer for `steps` steps of text.
    pub fn new(steps: usize) -> StepSizer {
        StepSizer {
            steps,
            written: 0,
            from: 0,
        }
    }

    /// Call before writing a step into `out`.
    pub fn start(&mut self, out: &str) {
        if self.written == 0 {
            self.from = out.len();
        }
    }

    /// Call after writing a step into `out`; `after` is room for what
    /// follows the steps.
    pub fn written(&mut self, out: &mut String, after: usize) {
        self.written += 1;
        if self.written == SAMPLE_STEPS && self.steps > 2 * SAMPLE_STEPS {
            let per_step = (out.len() - self.from) / SAMPLE_STEPS;
            let rest = (self.steps - SAMPLE_STEPS) * per_step;
            // A twentieth to spare.
            out.reserve(rest + rest / 20 + after);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// After the sample the buffer holds the rest without growing again.
    #[test]
    fn the_buffer_is_sized_once_for_the_rest() {
        let steps = 10_000;
        let mut out = String::with_capacity(16);
        let mut sizer = StepSizer::new(steps);
        let mut grew_after_sample = 0;
        for i in 0..steps {
            let cap = out.capacity();
            sizer.start(&out);
            out.push_str(&format!("step {i:05} of a plan\n"));
            sizer.written(&mut out, 0);
            if i > SAMPLE_STEPS && out.capacity() != cap {
                grew_after_sample += 1;
            }
        }
        assert_eq!(grew_after_sample, 0);
        assert!(out.capacity() < out.len() + out.len() / 10);
    }
}
