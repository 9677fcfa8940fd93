//! The poses of a file held flat: the commands of every pose in one vector, the line of every
//! pose in another, so that a program of millions of blocks costs 8 bytes per axis and 4 bytes
//! per pose (44 bytes a pose for five axes), not a vector per pose.

use crate::poses::CommandedPose;

/// The most poses read from one file (an NC program or a CSV of commanded poses): 10⁷. A
/// 256 MiB file ([`crate::poses::MAX_FILE_BYTES`]) of the shortest blocks (`C1` and a line
/// end) could hold 9·10⁷; 10⁷ poses of a five-axis machine hold 440 MB and take about 20 s of
/// processor time to correct. A file with more is refused before any pose is corrected,
/// without holding its poses.
pub const MAX_POSES: usize = 10_000_000;

/// Commanded poses in the order of their file: per pose, its 1-based line and the command of
/// every axis (in the order of the axis words the file was read for; mm and degrees as files
/// hold them, or mm and rad, as the holder says).
///
/// Held flat: one `f64` per axis and one `u32` per pose ([`PoseList::held_bytes`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PoseList {
    axes: usize,
    /// `axes` values per pose, pose after pose.
    commands: Vec<f64>,
    /// One per pose. Lines fit: a file of [`crate::poses::MAX_FILE_BYTES`] has fewer than
    /// 2³² lines.
    lines: Vec<u32>,
}

impl PoseList {
    /// An empty list of poses of `axes` axes, with room for `poses` poses.
    pub(crate) fn with_capacity(axes: usize, poses: usize) -> PoseList {
        PoseList {
            axes,
            commands: Vec::with_capacity(axes * poses),
            lines: Vec::with_capacity(poses),
        }
    }

    /// Appends the pose of `line` commanding `commands` (one value per axis).
    pub(crate) fn push(&mut self, line: usize, commands: &[f64]) {
        debug_assert_eq!(commands.len(), self.axes);
        self.commands.extend_from_slice(commands);
        self.lines.push(u32::try_from(line).unwrap_or(u32::MAX));
    }

    /// Gives back the room reserved beyond the poses held.
    pub(crate) fn shrink_to_fit(&mut self) {
        self.commands.shrink_to_fit();
        self.lines.shrink_to_fit();
    }

    /// The number of poses.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// `true` when the list holds no pose.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// The number of axes of every pose.
    pub fn axes(&self) -> usize {
        self.axes
    }

    /// The 1-based line of the file that holds pose `i` (every line counted).
    ///
    /// # Panics
    /// When `i` is not below [`PoseList::len`].
    pub fn line(&self, i: usize) -> usize {
        self.lines[i] as usize
    }

    /// The command of every axis at pose `i`.
    ///
    /// # Panics
    /// When `i` is not below [`PoseList::len`].
    pub fn commands(&self, i: usize) -> &[f64] {
        &self.commands[i * self.axes..(i + 1) * self.axes]
    }

    /// The poses in order: `(line, commands)`.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (usize, &[f64])> + '_ {
        self.lines
            .iter()
            .zip(self.commands.chunks_exact(self.axes.max(1)))
            .map(|(&l, c)| (l as usize, c))
    }

    /// Every pose copied out, one [`CommandedPose`] (with a vector of its own) per pose: for
    /// short lists and tests. About 80 bytes a pose of five axes, twice what the list holds.
    pub fn to_poses(&self) -> Vec<CommandedPose> {
        self.iter()
            .map(|(line, commands)| CommandedPose {
                line,
                commands: commands.to_vec(),
            })
            .collect()
    }

    /// The bytes the list holds on the heap (what it has reserved): 8 per axis and 4 per pose,
    /// `(8 · axes + 4) · len` once the reader has given back its spare room.
    pub fn held_bytes(&self) -> usize {
        self.commands.capacity() * size_of::<f64>() + self.lines.capacity() * size_of::<u32>()
    }
}

/// The poses of a file of `text`, read by `read` (which gives each pose, in order, to the sink
/// it is called with: its line and one command per axis of `axes`), held flat; at most
/// `max_poses`, beyond which the error is `too_many(line)` of the first pose too many.
///
/// The list is given room for one pose per line of the text, so that it never grows by
/// doubling (and is trimmed to its poses at the end). A text of more lines than `max_poses`
/// is read twice: once counting its poses (holding none, and refused there if there are too
/// many), once holding them.
pub(crate) fn read_flat<E>(
    text: &str,
    axes: usize,
    max_poses: usize,
    too_many: impl Fn(usize) -> E,
    mut read: impl FnMut(&mut dyn FnMut(usize, &[f64]) -> Result<(), E>) -> Result<(), E>,
) -> Result<PoseList, E> {
    let bound = text.bytes().filter(|&b| b == b'\n').count() + 1;
    let room = if bound > max_poses {
        let mut count = 0usize;
        read(&mut |line, _| {
            count += 1;
            if count > max_poses {
                return Err(too_many(line));
            }
            Ok(())
        })?;
        count
    } else {
        bound
    };
    let mut list = PoseList::with_capacity(axes, room);
    read(&mut |line, commands| {
        if list.len() == max_poses {
            return Err(too_many(line));
        }
        list.push(line, commands);
        Ok(())
    })?;
    list.shrink_to_fit();
    Ok(list)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poses_are_held_flat() {
        let mut l = PoseList::with_capacity(3, 4);
        l.push(2, &[1.0, 2.0, 3.0]);
        l.push(5, &[4.0, 5.0, 6.0]);
        l.shrink_to_fit();
        assert_eq!((l.len(), l.axes(), l.line(1)), (2, 3, 5));
        assert_eq!(l.commands(1), [4.0, 5.0, 6.0]);
        let lines: Vec<usize> = l.iter().map(|(line, _)| line).collect();
        assert_eq!(lines, [2, 5]);
        assert_eq!(l.to_poses()[0].commands, [1.0, 2.0, 3.0]);
        assert_eq!(l.held_bytes(), 2 * (3 * 8 + 4));
    }
}
