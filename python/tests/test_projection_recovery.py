"""The projection at a jammed vertex whose multipliers are recovered (quasistatics.cpp,
"Multipliers at a degenerate vertex"): the answer reports the working set the recovery ends
with, over as many rows as it has.

The three instances (a body between nearly opposite, nearly repeated rows: copies perturbed by
1e-12 to 1e-6, some negated) came from a seeded search of 20,000 such problems, as the ones
where the recovery ends with a working set of another size than the loop's (5 rows to 6, 6 to 5).
The result once reported the loop's row count with the recovered multipliers, and these three were
"uncertified" (kkt_relative 0.07, 5e-5, 1.5e-3)."""
import numpy as np
import pytest

import gauss6._gauss6 as g

# Each instance: M (6 x 6), au (6), J (m x 6), every double exact (float.hex).
INSTANCES = {
    4524: {
        "M": [
            ["0x1.e2bd3ef1a5922p+3", "0x1.049bab27f44a6p+2", "0x1.dfd2270efb34ep-4", "-0x1.5be4de141051ap+2", "-0x1.fe071e0fe5cd2p+0", "0x1.d9119cf946e81p+0"],
            ["0x1.049bab27f44a6p+2", "0x1.459aaea68c661p+3", "0x1.0f05c7e650d77p+1", "-0x1.77eee0b40a4c2p+0", "-0x1.fc3773a6847e5p+1", "0x1.c841865637081p+0"],
            ["0x1.dfd2270efb34ep-4", "0x1.0f05c7e650d77p+1", "0x1.6d458dd7d50b0p+3", "0x1.bb425ae396959p-1", "-0x1.80f37b0abfe79p+0", "0x1.623f93587c3cfp+1"],
            ["-0x1.5be4de141051ap+2", "-0x1.77eee0b40a4c2p+0", "0x1.bb425ae396959p-1", "0x1.0a334deb0a7e3p+4", "-0x1.680d718e1444fp+1", "-0x1.1f73391a6f9abp+2"],
            ["-0x1.fe071e0fe5cd2p+0", "-0x1.fc3773a6847e5p+1", "-0x1.80f37b0abfe79p+0", "-0x1.680d718e1444fp+1", "0x1.28eb821c18c5ap+4", "0x1.3987a77f77970p-1"],
            ["0x1.d9119cf946e81p+0", "0x1.c841865637081p+0", "0x1.623f93587c3cfp+1", "-0x1.1f73391a6f9abp+2", "0x1.3987a77f77970p-1", "0x1.53bcfc1c436e1p+3"],
        ],
        "au": ["0x1.b61257ba9344ep-15", "-0x1.51d9a5d579e82p-11", "-0x1.0080e1b3dce2bp-10", "-0x1.03ab053f9c338p-9", "-0x1.224e81c739001p-13", "0x1.b2e597236f1cbp-13"],
        "J": [
            ["-0x1.3b13b2cb8f2b5p+0", "-0x1.61313243ca658p-1", "-0x1.8c23c40f1cc3dp-7", "0x1.44e34d00b632ep-1", "-0x1.6c12e6b657b43p-4", "0x1.3e03aa0c729aep-1"],
            ["0x1.3b13b2cbdb3b4p+0", "0x1.6131324024aedp-1", "0x1.8c23c363ab36dp-7", "-0x1.44e34cffe8536p-1", "0x1.6c12e691dd0c4p-4", "-0x1.3e03aa0b2b047p-1"],
            ["-0x1.4cfb5b99d8557p-1", "-0x1.5b1167fd01d50p-7", "-0x1.fa9dee562f516p-2", "-0x1.ac320af0f439fp-2", "0x1.2065828d78bcap-1", "0x1.201628dac6652p-3"],
            ["-0x1.4cfb84cf23051p-1", "-0x1.5b0ab6d1da655p-7", "-0x1.fa9de839ae9e5p-2", "-0x1.ac323533469f2p-2", "0x1.20658254d8968p-1", "0x1.2015df33bf37bp-3"],
            ["0x1.4cfb84cf26110p-1", "0x1.5b0ab6d206241p-7", "0x1.fa9de839a3d7dp-2", "0x1.ac3235333880cp-2", "-0x1.20658254d63a8p-1", "-0x1.2015df33c5694p-3"],
            ["-0x1.4e3d9202c248fp-2", "0x1.a03c7d573d0d8p-3", "0x1.eebb4c19f978bp-2", "0x1.27d5e14b11345p+0", "0x1.9124af47d681cp-4", "0x1.a85f5a43013cdp-6"],
            ["-0x1.4e3d92b6efdf2p-2", "0x1.a03c7db904581p-3", "0x1.eebb4c55e8f61p-2", "0x1.27d5e10509888p+0", "0x1.9124a92159cf1p-4", "0x1.a85f53c2e2424p-6"],
            ["0x1.4e3d92b7629e0p-2", "-0x1.a03c7db9ed6d3p-3", "-0x1.eebb4c5473e3fp-2", "-0x1.27d5e104dac2cp+0", "-0x1.9124a92341fc6p-4", "-0x1.a85f53c7960cbp-6"],
        ],
    },
    14853: {
        "M": [
            ["0x1.c838df34657fcp+2", "0x1.0a48124490996p-1", "-0x1.056098505318fp+0", "-0x1.134e4d735b04ep-2", "-0x1.34bff4fe4e84fp-4", "0x1.d84e101dd8d42p+0"],
            ["0x1.0a48124490996p-1", "0x1.e499c57493d38p+3", "0x1.e16c78d4f807bp-2", "-0x1.d6bc68761f7f3p-4", "-0x1.27c464bf07c90p+2", "0x1.0c88701e91a74p+2"],
            ["-0x1.056098505318fp+0", "0x1.e16c78d4f807bp-2", "0x1.24025a8add0c7p+3", "0x1.18f416d858fe1p-3", "0x1.ef3e7148f672ep+0", "0x1.8b47fd291ab4ep+0"],
            ["-0x1.134e4d735b04ep-2", "-0x1.d6bc68761f7f3p-4", "0x1.18f416d858fe1p-3", "0x1.9ed2d658542c1p+2", "-0x1.fb2a9e19f1982p-2", "0x1.684c5abec9721p-4"],
            ["-0x1.34bff4fe4e84fp-4", "-0x1.27c464bf07c90p+2", "0x1.ef3e7148f672ep+0", "-0x1.fb2a9e19f1982p-2", "0x1.ab17d57897826p+3", "0x1.8486252045491p+0"],
            ["0x1.d84e101dd8d42p+0", "0x1.0c88701e91a74p+2", "0x1.8b47fd291ab4ep+0", "0x1.684c5abec9721p-4", "0x1.8486252045491p+0", "0x1.fd215a55428b3p+3"],
        ],
        "au": ["-0x1.5b0106fcf5c3bp+4", "-0x1.c7d6f4f8e546dp+3", "0x1.9fc3c7eab5dc5p+4", "0x1.ae459e1cc0c91p+2", "0x1.66f02951bb004p+3", "-0x1.5f90ba37a1fe8p+3"],
        "J": [
            ["0x1.ed706449db2bap-3", "0x1.04cea68973824p+1", "-0x1.35092f7f52e19p-2", "0x1.e9831fa209a6ap-1", "-0x1.5f93271d1eec2p+1", "0x1.1ebf2138a74a0p-3"],
            ["0x1.ed7064499467dp-3", "0x1.04cea68970835p+1", "-0x1.35092f7f98cc9p-2", "0x1.e9831fa22d92dp-1", "-0x1.5f93271d1bcbbp+1", "0x1.1ebf213a00085p-3"],
            ["0x1.a13aaea8ab94dp-1", "-0x1.213a8ee7b6310p-3", "-0x1.867df369ee648p+0", "-0x1.b9e6fd7dee50dp+0", "0x1.e691ec08aa572p-2", "0x1.122ab832b93b1p+0"],
            ["0x1.a13aaea83e6d2p-1", "-0x1.213a8ee765e93p-3", "-0x1.867df36f6c4a3p+0", "-0x1.b9e6fd7af0161p+0", "0x1.e691ec0384984p-2", "0x1.122ab83527419p+0"],
            ["0x1.a13aaed957d93p-1", "-0x1.213a8d1a604dap-3", "-0x1.867df34755269p+0", "-0x1.b9e6fd1c3723ep+0", "0x1.e691ec0acdeb2p-2", "0x1.122ab87795434p+0"],
            ["-0x1.a13aaea7a4770p-1", "0x1.213a8ee87209fp-3", "0x1.867df37143ed1p+0", "0x1.b9e6fd7b5f0c7p+0", "-0x1.e691ec015de7fp-2", "-0x1.122ab83410161p+0"],
            ["0x1.47c94dde118eap+0", "-0x1.b690b7a62d67fp-2", "-0x1.611c1b524dec6p+0", "-0x1.aa5af8aa2db68p+0", "-0x1.0e3eb0e1ea0a4p-1", "-0x1.efdaa7fa06447p+0"],
            ["0x1.47c94dde0d83ep+0", "-0x1.b690b7a6b9988p-2", "-0x1.611c1b5246c3fp+0", "-0x1.aa5af8aa0f8a0p+0", "-0x1.0e3eb0e1d7107p-1", "-0x1.efdaa7f9e98b1p+0"],
            ["0x1.47c94dde1b8bfp+0", "-0x1.b690b7a6e0c21p-2", "-0x1.611c1b5257843p+0", "-0x1.aa5af8aa029ebp+0", "-0x1.0e3eb0e1ebeffp-1", "-0x1.efdaa7f9d72afp+0"],
            ["-0x1.47c94dde2bcd0p+0", "0x1.b690b7a41391bp-2", "0x1.611c1b4facd8fp+0", "0x1.aa5af8a6a1d4ep+0", "0x1.0e3eb0df431c0p-1", "0x1.efdaa7f99ca4ap+0"],
            ["0x1.d29ca05a5993dp+0", "0x1.c6711163b7b69p-1", "-0x1.99310f076ce4ep+0", "0x1.0428286a4bf26p-1", "-0x1.38ad728dbd87bp-2", "0x1.c946a7146297dp-2"],
            ["0x1.d29ca93e5bdb8p+0", "0x1.c67121ab992b7p-1", "-0x1.99310ce111cb5p+0", "0x1.04282c164a8d7p-1", "-0x1.38ad6144953e3p-2", "0x1.c946b1bf8703bp-2"],
            ["0x1.d29ca0e0de268p+0", "0x1.c671130b6c99cp-1", "-0x1.99311044de02fp+0", "0x1.042827f51cd01p-1", "-0x1.38ad72a727e5dp-2", "0x1.c946a89cde930p-2"],
        ],
    },
    17242: {
        "M": [
            ["0x1.b64f2395ac721p+3", "0x1.9940a095183e5p+1", "0x1.4736749a7154fp+1", "-0x1.769de9dc6caefp+1", "-0x1.8a2988c683d51p+1", "0x1.ad9833ea4eee9p+2"],
            ["0x1.9940a095183e5p+1", "0x1.525363f1e14cfp+3", "0x1.24b5336f10dcdp-2", "0x1.8355aa2f7dcb4p+0", "-0x1.bc946f9139530p+1", "0x1.14640de85292ap+2"],
            ["0x1.4736749a7154fp+1", "0x1.24b5336f10dcdp-2", "0x1.54b3c1597285ep+3", "-0x1.e01f37afec449p+1", "-0x1.8a545c4a913dap+1", "0x1.deecace217ec5p+1"],
            ["-0x1.769de9dc6caefp+1", "0x1.8355aa2f7dcb4p+0", "-0x1.e01f37afec449p+1", "0x1.a24fc63086b20p+3", "-0x1.a584f5344905dp+0", "-0x1.24c0e854c6dd9p+2"],
            ["-0x1.8a2988c683d51p+1", "-0x1.bc946f9139530p+1", "-0x1.8a545c4a913dap+1", "-0x1.a584f5344905dp+0", "0x1.ba2214e57d8a0p+3", "-0x1.e05c804013807p+1"],
            ["0x1.ad9833ea4eee9p+2", "0x1.14640de85292ap+2", "0x1.deecace217ec5p+1", "-0x1.24c0e854c6dd9p+2", "-0x1.e05c804013807p+1", "0x1.0f47f409f765bp+4"],
        ],
        "au": ["-0x1.3e192af5f604ap-4", "0x1.b09f63c5c9fc4p-7", "-0x1.d49fefdbba8a2p-6", "-0x1.4444985a05ac3p-5", "-0x1.8bb55e731369ep-7", "-0x1.4fd28bb1e2bf3p-5"],
        "J": [
            ["-0x1.14f3173721d4ap-1", "0x1.8ca3e70735638p-1", "0x1.3a468946cfcddp-1", "0x1.027ae18bdc738p+1", "0x1.1bfeb385803bdp-1", "0x1.dba17a4114db7p-4"],
            ["-0x1.fd4eb3bc1c6efp+0", "-0x1.94de199465dcap-4", "0x1.2b1079d0a3f66p+0", "-0x1.48f6b8c0b56e6p+0", "-0x1.4f8634ec4759dp-2", "-0x1.4849cb160a191p-3"],
            ["-0x1.fd4eb3b8d3bc8p+0", "-0x1.94de193d6f01bp-4", "0x1.2b1079cf3c234p+0", "-0x1.48f6b8c20fcb4p+0", "-0x1.4f8634f3d76ebp-2", "-0x1.4849cb1f3a711p-3"],
            ["0x1.fd4eb3bbfe0ecp+0", "0x1.94de199633e60p-4", "-0x1.2b1079d085d02p+0", "0x1.48f6b8c0a54ddp+0", "0x1.4f8634ec9475dp-2", "0x1.4849cb16ef143p-3"],
            ["0x1.a2696dffc9323p+0", "-0x1.ccc70427dc2d4p-1", "0x1.9a9ad1d800f4cp+0", "-0x1.9542d2159f2dfp-2", "-0x1.7f085f66de18dp-5", "0x1.528258ab44c1dp+0"],
            ["-0x1.a2696ec78de88p+0", "0x1.ccc703e5efca7p-1", "-0x1.9a9ad206c5969p+0", "0x1.9542d143b4204p-2", "0x1.7f0845c6231abp-5", "-0x1.528258cebfb4cp+0"],
        ],
    },
}


def as_array(rows):
    return np.array([[float.fromhex(x) for x in r] if isinstance(r, list) else float.fromhex(r) for r in rows])


@pytest.mark.parametrize("seed_index", sorted(INSTANCES))
def test_recovered_working_set_is_reported_whole(seed_index):
    d = {k: as_array(v) for k, v in INSTANCES[seed_index].items()}
    M, au, J = d["M"], d["au"], d["J"]
    p = g.project(M, au, J)
    # "optimal" is the solver's own scale-free certificate: kkt_relative <= certificate_tol.
    assert p.status == "optimal", (p.status, p.kkt_relative)
    active = list(p.active)
    assert len(set(active)) == len(active)
    # Multipliers only on the reported rows, none negative.
    assert all(p.lam[k] == 0 for k in range(len(J)) if k not in active)
    assert all(p.lam[k] >= 0 for k in active)
    # Stationarity measured here, independently of the solver: |M (ac - au) - J^T lam|_{M^-1}
    # over the sum of the lengths it adds up (|ac - au|_M and each lam_k |J_k|_{M^-1}).
    # 1e-10: far above the rounding of that sum (a few hundred eps of it, the multipliers
    # being large), far below what the loop's row count with the recovered multipliers left.
    L_inv = np.linalg.inv(np.linalg.cholesky(M))
    g_res = M @ (p.ac - au) - J.T @ p.lam
    row_norms = np.linalg.norm(J @ L_inv.T, axis=1)
    scale = np.linalg.norm(np.linalg.cholesky(M).T @ (p.ac - au)) + np.sum(np.abs(p.lam) * row_norms)
    assert np.linalg.norm(L_inv @ g_res) <= 1e-10 * scale
