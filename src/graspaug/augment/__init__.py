"""The paper's method, Section III of *Improving Robotic Grasping Ability Through Deep Shape Generation*, in order.

- :mod:`~graspaug.augment.corpus`: the corpus made usable: each file one closed solid, scaled, split (III-A's data);
- :mod:`~graspaug.augment.scores`: rarity (eqs. (3)-(4), on the AE-Critic latents) and graspness (the share of
  robust antipodal grasps); :mod:`~graspaug.augment.score_tables`: the tables, histograms and summaries of both;
- :mod:`~graspaug.augment.embedding`: the 2-D t-SNE map of the latents (Fig. 1);
- :mod:`~graspaug.augment.candidates`: base sets, pairs of rare / graspable neighbours, the α schedule and the
  candidate streams of every pool (targeted, random, recon, failure), and the pool tables (III-C);
- :mod:`~graspaug.augment.decode`: the batch runners that turn candidates into meshes (decode → fill → open →
  marching cubes → smooth), and the no-network ones (blend, warp, primitives, procedural);
- :mod:`~graspaug.augment.pools`: the ``generate`` stage's pools of one base set, filled and tabled;
- :mod:`~graspaug.augment.failures`: shapes near the objects a planner fails on: the ``from-failures`` stream and
  the lifelong loop's rounds (its failure and random arms).

The AutoEncoder-Critic itself (III-B) is :mod:`graspaug.nets.ae_critic`, with the batched ``encode`` / ``decode``
that generation runs (augment imports no training code); its training loop is :mod:`graspaug.training.autoencoder`;
the decoded grid becomes a mesh in :mod:`graspaug.geometry.from_voxels`.
"""
