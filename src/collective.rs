//! Making failures collective: an error on one rank must end every rank cleanly,
//! never leave the others waiting in a collective call.
use crate::error::Error;
use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

/// Every rank passes its local outcome; all ranks get `Ok` only if all succeeded. The
/// failing ranks keep their own error; the others get [`Error::PeerFailed`].
pub fn agree<T>(world: &SimpleCommunicator, local: Result<T, Error>) -> Result<T, Error> {
    let flag: i32 = if local.is_ok() { 1 } else { 0 };
    let mut all: i32 = 0;
    world.all_reduce_into(&flag, &mut all, SystemOperation::min());
    match local {
        Ok(v) if all == 1 => Ok(v),
        Ok(_) => Err(Error::PeerFailed),
        Err(e) => Err(e),
    }
}

/// Whether `flag` holds on every rank.
pub fn all(world: &SimpleCommunicator, flag: bool) -> bool {
    let mut out: i32 = 0;
    world.all_reduce_into(&(flag as i32), &mut out, SystemOperation::min());
    out == 1
}

/// The maximum of a value over all ranks.
pub fn max_f64(world: &SimpleCommunicator, v: f64) -> f64 {
    let mut out = 0.0;
    world.all_reduce_into(&v, &mut out, SystemOperation::max());
    out
}

/// The sum of a value over all ranks.
pub fn sum_f64(world: &SimpleCommunicator, v: f64) -> f64 {
    let mut out = 0.0;
    world.all_reduce_into(&v, &mut out, SystemOperation::sum());
    out
}

/// Rank 0's values on every rank (the length too): for data every rank computed from the
/// same global state, which a mesh or a marking built on each rank must see bit for bit.
pub fn from_rank0(world: &SimpleCommunicator, local: &[f64]) -> Vec<f64> {
    let root = world.process_at_rank(0);
    let mut n = local.len() as u64;
    root.broadcast_into(&mut n);
    let mut out = if world.rank() == 0 { local.to_vec() } else { vec![0.0; n as usize] };
    root.broadcast_into(&mut out[..]);
    out
}

/// Every rank's `local` values, concatenated in rank order, on every rank.
pub fn all_gather_f64(world: &SimpleCommunicator, local: &[f64]) -> Vec<f64> {
    let size = world.size() as usize;
    let mut counts = vec![0i32; size];
    world.all_gather_into(&(local.len() as i32), &mut counts[..]);
    let displs: Vec<i32> = counts.iter().scan(0, |acc, &n| Some(std::mem::replace(acc, *acc + n))).collect();
    let mut out = vec![0.0; counts.iter().map(|&n| n as usize).sum()];
    {
        let mut part = mpi::datatype::PartitionMut::new(&mut out[..], &counts[..], &displs[..]);
        world.all_gather_varcount_into(local, &mut part);
    }
    out
}
