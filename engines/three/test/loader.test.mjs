// The loader's handling of the paths a manifest names (node --test): a manifest is untrusted, so
// a path resolves inside the bake folder or is refused.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { BakeError, resolveInside } from '../src/index.js';

const base = new URL('http://127.0.0.1:8000/bakes/gold/');

test('relative paths resolve inside the bake folder', () => {
    assert.equal(resolveInside(base, 'engine-merl.ktx2').href, 'http://127.0.0.1:8000/bakes/gold/engine-merl.ktx2');
    assert.equal(resolveInside(base, 'sub/a b.ktx2').href, 'http://127.0.0.1:8000/bakes/gold/sub/a%20b.ktx2');
});

test('paths that leave the folder are refused', () => {
    for (const path of ['../x.ktx2', 'a/../../x', '/etc/passwd', 'http://evil.example/x', '//evil.example/x', 'C:\\x',
        'a\\..\\x', '%2e%2e/x', './x', 'a//b', '', 'x?y', 'x#y', null, 3]) {
        assert.throws(() => resolveInside(base, path), BakeError, `accepted ${JSON.stringify(path)}`);
    }
});
