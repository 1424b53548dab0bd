#!/usr/bin/env python3
"""Counts the public items of a crate as a user sees them in its docs: every item reachable
from the crate root through public modules and re-exports, with inherent methods and trait
items, without `#[doc(hidden)]` ones (each item once, however many paths reach it).

    cargo +nightly rustdoc -p dhcd --lib -- -Zunstable-options --output-format json
    python3 benches/scripts/public-items.py target/doc/dhcd.json [--list]
"""
import json,sys,collections
d=json.load(open(sys.argv[1]))
idx=d['index']; root=d['root']
crate_id=idx[str(root)]['crate_id'] if str(root) in idx else 0
def hidden(it):
    return any('doc(hidden)' in str(a) for a in it.get('attrs',[]))
seen=set(); counts=collections.Counter(); names=[]
def kind(it): return next(iter(it['inner']))
def visit(i,path):
    i=str(i)
    if i in seen or i not in idx: return
    it=idx[i]
    if it.get('crate_id')!=crate_id: return
    if hidden(it): return
    seen.add(i)
    k=kind(it)
    if k=='use':
        u=it['inner']['use']
        if u.get('id') is not None:
            tgt=idx.get(str(u['id']))
            if u.get('is_glob') and tgt and kind(tgt)=='module':
                for c in tgt['inner']['module']['items']: visit(c,path)
            else: visit(u['id'],path)
        return
    if it.get('visibility')!='public' and k not in ('impl',): return
    name=it.get('name')
    p=path+'::'+name if name else path
    if k!='impl':
        counts[k]+=1; names.append((k,p))
    if k=='module':
        for c in it['inner']['module']['items']: visit(c,p)
    elif k in ('struct','enum','union','trait'):
        inner=it['inner'][k]
        if k=='enum':
            for v in inner['variants']: pass
        if k=='trait':
            for c in inner['items']: 
                ci=idx.get(str(c))
                if ci and not hidden(ci): counts['trait_item']+=1; names.append(('trait_item',p+'::'+(ci.get('name') or '')))
        for im in inner.get('impls',[]):
            imi=idx.get(str(im))
            if not imi: continue
            imp=imi['inner']['impl']
            if imp.get('trait') is not None or imp.get('is_synthetic') or imp.get('blanket_impl'): continue
            for c in imp['items']:
                ci=idx.get(str(c))
                if ci and ci.get('visibility')=='public' and not hidden(ci):
                    counts['method']+=1; names.append(('method',p+'::'+ci['name']))
visit(root, idx[str(root)]['name'])
print(sum(counts.values()), dict(counts))
if '--list' in sys.argv[2:]:
    for k,p in sorted(names,key=lambda x:x[1]): print(k,p)
